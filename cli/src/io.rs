//! Mesh files: OBJ, PLY (ascii and binary), STL (ascii and binary) and glTF 2.0 (`.gltf`,
//! `.glb`) in; OBJ, binary PLY and binary STL out. `-` is standard input (format found from
//! the bytes) or standard output (the format given by the caller, OBJ by default).
//!
//! Only positions and faces are read: attributes (texture coordinates, normals, colours, any
//! other PLY property, every glTF attribute but POSITION) are not carried, and [`LoadNotes`]
//! says which were dropped. Faces with more than three corners (quads, n-gons, concave ones
//! too) are split into triangles by ear clipping ([`triangulate`]), and [`LoadNotes`] counts
//! them.
//!
//! * **OBJ**: only `v` and `f` lines matter (`vt`, `vn`, `o`, `g`, `s`, `usemtl`, `l`, `p`, ...
//!   are ignored). Vertices keep the file's numbering exactly, unreferenced ones included; face
//!   corners may be written `a`, `a/b`, `a//c` or `a/b/c` and may be negative (relative).
//!   Faces with fewer than three corners are rejected. This is a small reader of our own: `tobj`
//!   always renumbers vertices in order of first use and drops unreferenced ones (checked in
//!   tobj 4.0.5, `add_vertex`/`add_vertex_multi_index`), so it cannot keep the file's
//!   numbering; `tobj` is used in the tests as an independent cross-check of the geometry.
//! * **PLY**: via `ply-rs-bw`; element `vertex` (`x`, `y`, `z`, any scalar type) and element
//!   `face` (list `vertex_indices` or `vertex_index`; polygons are triangulated).
//! * **STL**: via `stl_io`; corners are welded by bit-exact `f32` position, vertices numbered
//!   by first appearance. A file is binary when its size is exactly `84 + 50 n` bytes with `n`
//!   the triangle count at offset 80, even if its header starts with `solid` (`stl_io` 0.11
//!   alone would take such a file for ascii and fail).
//! * **glTF**: read by [`gltf`] (every length and count checked), then seen as `simplify` sees
//!   it ([`gltf::geometry`]): every TRIANGLES primitive once, in file order, in its mesh's own
//!   coordinates, its vertices numbered after the previous primitive's. Node transforms are
//!   not applied and a mesh that several nodes place (instancing) counts once, so every
//!   command that reads a mesh counts the triangles `simplify` counts; [`LoadNotes`] says when
//!   the scene draws the meshes otherwise (`render` draws the scene as placed). A `.gltf`'s
//!   external buffers are read beside it; on standard input a GLB is known by its `glTF`
//!   magic, a `.gltf` by its `{`, and then only embedded (`data:`) buffers are read.
//!
//! Every error names the file and, where it can, the line (text) or byte offset (binary).
//! A file without any triangle is an error, and so is a non-finite coordinate of a vertex a
//! face uses or a face index past the last vertex. A vertex no face uses may hold NaN, as it
//! may in the library (which only checks the vertices its triangles use).

use std::collections::HashMap;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};

mod obj;
mod ply;
mod stl;

use obj::{obj_bytes, parse_obj};
use ply::{parse_ply, ply_bytes};
use stl::{parse_stl, stl_bytes, stl_size_matches_binary};

pub mod gltf;
pub mod objattr;
pub mod plyattr;

/// A triangle mesh: positions and 0-based vertex indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions, in file order (unreferenced vertices included).
    pub positions: Vec<[f32; 3]>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

impl MeshData {
    /// Axis-aligned bounding box `(min, max)` of the vertices that in-range triangles use, in
    /// f64; `None` if no triangle uses a vertex.
    pub fn bbox(&self) -> Option<([f64; 3], [f64; 3])> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut any = false;
        for t in &self.triangles {
            for &i in t {
                if let Some(p) = self.positions.get(i as usize) {
                    any = true;
                    for k in 0..3 {
                        lo[k] = lo[k].min(f64::from(p[k]));
                        hi[k] = hi[k].max(f64::from(p[k]));
                    }
                }
            }
        }
        any.then_some((lo, hi))
    }

    /// Length of the bounding-box diagonal over referenced vertices (0 for an empty mesh).
    pub fn bbox_diagonal(&self) -> f64 {
        match self.bbox() {
            Some((lo, hi)) => (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt(),
            None => 0.0,
        }
    }
}

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Wavefront OBJ (text).
    Obj,
    /// PLY (binary little endian when written).
    Ply,
    /// STL (binary when written).
    Stl,
}

/// What a reader did besides copying triangles: polygons it split, attributes it dropped.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LoadNotes {
    /// Faces with more than three corners, split into triangles.
    pub polygons_split: usize,
    /// Triangles those faces became.
    pub triangles_from_polygons: usize,
    /// Attributes that were in the file and are not carried, e.g. "1204 texture coordinates
    /// (vt)" or "vertex properties nx, ny, nz".
    pub dropped: Vec<String>,
    /// Anything else worth a line, e.g. how a glTF scene places its meshes.
    pub other: Vec<String>,
}

impl LoadNotes {
    /// One line per note, for stderr; none if there is nothing to say.
    pub fn lines(&self, name: &str) -> Vec<String> {
        let mut out = Vec::new();
        if self.polygons_split > 0 {
            out.push(format!(
                "note: {name}: {} polygon(s) with more than 3 corners split into {} triangles",
                self.polygons_split, self.triangles_from_polygons
            ));
        }
        if !self.dropped.is_empty() {
            out.push(format!(
                "warning: {name}: attributes are not carried, dropped: {}",
                self.dropped.join("; ")
            ));
        }
        out.extend(self.other.iter().map(|o| format!("note: {name}: {o}")));
        out
    }
}

/// Whether `path` means standard input or output.
pub fn is_std(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// The format a path's extension names (`.obj`, `.ply`, `.stl`, any case).
pub fn format_of(path: &Path) -> Result<Format> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => Ok(Format::Obj),
        Some("ply") => Ok(Format::Ply),
        Some("stl") => Ok(Format::Stl),
        _ => bail!(
            "{}: unknown mesh format (expected extension .obj, .ply or .stl)",
            path.display()
        ),
    }
}

/// The format of mesh bytes read from standard input: PLY by its magic, STL by a binary size or
/// an ascii `solid` header with `facet` lines, else OBJ.
pub fn sniff(bytes: &[u8]) -> Format {
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
        return Format::Ply;
    }
    if stl_size_matches_binary(bytes) {
        return Format::Stl;
    }
    let head = &bytes[..bytes.len().min(4096)];
    if bytes.trim_ascii_start().starts_with(b"solid") && head.windows(5).any(|w| w == b"facet") {
        return Format::Stl;
    }
    Format::Obj
}

/// Loads a triangle mesh, choosing the format by extension (`.obj`, `.ply`, `.stl`, `.gltf`,
/// `.glb`, any case); `-` reads standard input and finds the format from the bytes ([`sniff`],
/// and glTF by [`is_gltf_bytes`]).
pub fn load(path: impl AsRef<Path>) -> Result<MeshData> {
    load_with_notes(path).map(|(m, _)| m)
}

/// [`load`], and what the reader split or dropped.
pub fn load_with_notes(path: impl AsRef<Path>) -> Result<(MeshData, LoadNotes)> {
    let path = path.as_ref();
    if gltf::is_gltf_path(path) {
        let file = gltf::load(path)?;
        let (mesh, notes) = gltf::geometry(&file);
        validate(&mesh).map_err(|e| anyhow!("{}: {e}", path.display()))?;
        return Ok((mesh, notes));
    }
    let (bytes, format, name) = if is_std(path) {
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut std::io::stdin().lock(), &mut bytes)
            .context("standard input: cannot read")?;
        if is_gltf_bytes(&bytes) {
            let (mesh, notes) = parse_gltf(&bytes).map_err(|e| anyhow!("standard input: {e}"))?;
            return Ok((mesh, notes));
        }
        let f = sniff(&bytes);
        (bytes, f, "standard input".to_string())
    } else {
        let format = format_of(path).map_err(|_| {
            anyhow!(
                "{}: unknown mesh format (expected extension .obj, .ply, .stl, .gltf or .glb)",
                path.display()
            )
        })?;
        let bytes =
            std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
        (bytes, format, path.display().to_string())
    };
    let (mesh, notes) = parse_format(&bytes, format).map_err(|e| anyhow!("{name}: {e}"))?;
    validate(&mesh).map_err(|e| anyhow!("{name}: {e}"))?;
    Ok((mesh, notes))
}

/// [`load_with_notes`] for the command line: prints the notes on stderr.
pub fn load_noting(path: impl AsRef<Path>) -> Result<MeshData> {
    let path = path.as_ref();
    let (m, notes) = load_with_notes(path)?;
    let name = if is_std(path) {
        "standard input".to_string()
    } else {
        path.display().to_string()
    };
    for l in notes.lines(&name) {
        eprintln!("{l}");
    }
    Ok(m)
}

type Parsed = std::result::Result<(MeshData, LoadNotes), String>;

/// Whether mesh bytes are glTF: a GLB (`glTF` magic) or a JSON document (first non-blank
/// byte `{`, which no OBJ, PLY or STL starts with).
pub fn is_gltf_bytes(bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF") || bytes.trim_ascii_start().starts_with(b"{")
}

/// glTF bytes as [`gltf::geometry`] sees them, checked as [`load`] checks; only embedded
/// buffers are read.
fn parse_gltf(bytes: &[u8]) -> Parsed {
    let file = gltf::parse(bytes, None)?;
    let (mesh, notes) = gltf::geometry(&file);
    validate(&mesh)?;
    Ok((mesh, notes))
}

fn parse_format(bytes: &[u8], format: Format) -> Parsed {
    match format {
        Format::Obj => parse_obj(bytes),
        Format::Ply => parse_ply(bytes),
        Format::Stl => parse_stl(bytes).map(|m| (m, LoadNotes::default())),
    }
}

/// Parses a mesh from memory, the format given by `ext` (`obj`, `ply`, `stl`, `gltf` or `glb`,
/// any case, no dot), with the checks of [`load`]; a glTF's buffers must be embedded. Errors
/// carry no file name. Used by the fuzz targets.
pub fn parse_bytes(bytes: &[u8], ext: &str) -> Result<MeshData> {
    let format = match ext.to_ascii_lowercase().as_str() {
        "obj" => Format::Obj,
        "ply" => Format::Ply,
        "stl" => Format::Stl,
        "gltf" | "glb" => return parse_gltf(bytes).map(|(m, _)| m).map_err(|e| anyhow!(e)),
        _ => bail!("unknown mesh format {ext:?} (expected obj, ply, stl, gltf or glb)"),
    };
    let (mesh, _) = parse_format(bytes, format).map_err(|e| anyhow!(e))?;
    validate(&mesh).map_err(|e| anyhow!(e))?;
    Ok(mesh)
}

/// Checks what every loader promises: some triangles, indices in range, finite coordinates
/// for every vertex a triangle uses. A vertex no triangle uses may hold anything, NaN
/// included: the library never reads it (it checks only the vertices its triangles use), and
/// output files drop it unless the numbering is kept.
fn validate(mesh: &MeshData) -> std::result::Result<(), String> {
    if mesh.triangles.is_empty() {
        return Err("no triangles in file".into());
    }
    let n = mesh.positions.len();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(format!(
                "face {} refers to vertex {} but there are only {n} vertices",
                t + 1,
                u64::from(i) + 1
            ));
        }
    }
    let used = used_vertices(&mesh.positions, &mesh.triangles, &[]);
    if let Some(v) = mesh
        .positions
        .iter()
        .zip(&used)
        .position(|(p, &u)| u && p.iter().any(|c| !c.is_finite()))
    {
        return Err(format!(
            "vertex {} has a non-finite coordinate and a triangle uses it",
            v + 1
        ));
    }
    Ok(())
}

/// Saves a mesh, choosing the format by extension: `.obj` (text, 1-based, shortest round-trip
/// coordinates), `.ply` (binary little endian, `float` x y z, `list uchar int
/// vertex_indices`) or `.stl` (binary, facet normals computed). All positions are written, so
/// the vertex numbering is kept ([`compact`] drops unreferenced vertices first).
pub fn save(path: impl AsRef<Path>, mesh: &MeshData) -> Result<()> {
    let path = path.as_ref();
    let format = output_format(path, None)?;
    save_as(path, format, mesh)
}

/// The format an output path will be written in: `format` if given, else the extension's;
/// standard output (`-`) is OBJ unless `format` says otherwise.
pub fn output_format(path: &Path, format: Option<Format>) -> Result<Format> {
    match format {
        Some(f) => Ok(f),
        None if is_std(path) => Ok(Format::Obj),
        None => format_of(path),
    }
}

/// Checks, before any long work, that `path` can be written in a known format: the format is
/// known, the path is not a directory, its folder exists and the file can be created or opened
/// for writing. Creates nothing that was not there (a new file made for the test is removed)
/// and never truncates an existing file. Returns the format.
pub fn check_writable(path: &Path, format: Option<Format>) -> Result<Format> {
    let f = output_format(path, format)?;
    if is_std(path) {
        return Ok(f);
    }
    if path.is_dir() {
        bail!("{}: is a directory, not a file to write", path.display());
    }
    if path.exists() {
        std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .with_context(|| format!("{}: cannot write", path.display()))?;
    } else {
        std::fs::File::create(path)
            .with_context(|| format!("{}: cannot create", path.display()))?;
        let _ = std::fs::remove_file(path);
    }
    Ok(f)
}

/// Whether `output` names the file `input` is (standard input and output never do): the
/// same canonical path, so `./a.stl`, `dir/../a.stl` and a symbolic link to it all count.
/// An output that does not exist yet is not an input.
pub fn same_file(input: &Path, output: &Path) -> bool {
    if is_std(input) || is_std(output) || !output.exists() {
        return false;
    }
    match (input.canonicalize(), output.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Saves `mesh` to `path` (`-`: standard output) in `format`.
pub fn save_as(path: &Path, format: Format, mesh: &MeshData) -> Result<()> {
    let name = if is_std(path) {
        "standard output".to_string()
    } else {
        path.display().to_string()
    };
    let bytes = encode(format, mesh).map_err(|e| anyhow!("{name}: {e}"))?;
    if is_std(path) {
        let mut out = std::io::stdout().lock();
        return out
            .write_all(&bytes)
            .and_then(|()| out.flush())
            .with_context(|| format!("{name}: cannot write"));
    }
    let file = std::fs::File::create(path).with_context(|| format!("{name}: cannot create"))?;
    let mut w = BufWriter::new(file);
    w.write_all(&bytes)
        .and_then(|()| w.flush())
        .with_context(|| format!("{name}: cannot write"))?;
    Ok(())
}

/// The bytes of `mesh` in `format`.
pub fn encode(format: Format, mesh: &MeshData) -> std::result::Result<Vec<u8>, String> {
    match format {
        Format::Obj => Ok(obj_bytes(mesh)),
        Format::Ply => ply_bytes(mesh),
        Format::Stl => stl_bytes(mesh),
    }
}

/// `mesh` without the vertices no triangle uses; the others keep their order (so vertex `i`
/// of the result is the `i`-th used vertex of `mesh`). Returns the result and, for each of its
/// vertices, the index it had in `mesh`.
pub fn compact(mesh: &MeshData) -> (MeshData, Vec<u32>) {
    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &i in t {
            if let Some(u) = used.get_mut(i as usize) {
                *u = true;
            }
        }
    }
    let mut new_of = vec![u32::MAX; mesh.positions.len()];
    let mut old_of = Vec::new();
    let mut positions = Vec::new();
    for (i, p) in mesh.positions.iter().enumerate() {
        if used[i] {
            new_of[i] = old_of.len() as u32;
            old_of.push(i as u32);
            positions.push(*p);
        }
    }
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| new_of.get(i as usize).copied().unwrap_or(u32::MAX)))
        .collect();
    (
        MeshData {
            positions,
            triangles,
        },
        old_of,
    )
}

/// Maps the vertices of `output`, a mesh written in its own numbering (unreferenced vertices
/// dropped by [`compact`], or an STL file welded by position), back onto `input`'s numbering
/// by position (bit for bit), among the input vertices some input triangle uses. When the
/// output keeps the input's order (as [`compact`] does), each output vertex takes the next
/// match in order; otherwise the first match. Returns the renumbered output and how many
/// output vertices had another used input vertex at the same position (where the match may
/// be the wrong twin), or `None` if some output vertex is at no input vertex's position.
pub fn renumber_onto(input: &MeshData, output: &MeshData) -> Option<(MeshData, usize)> {
    let mut used = vec![false; input.positions.len()];
    for t in &input.triangles {
        for &i in t {
            if let Some(u) = used.get_mut(i as usize) {
                *u = true;
            }
        }
    }
    let key = |p: &[f32; 3]| p.map(f32::to_bits);
    let mut at: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
    for (i, p) in input.positions.iter().enumerate() {
        if used[i] {
            at.entry(key(p)).or_default().push(i as u32);
        }
    }
    let mut ambiguous = 0;
    for p in &output.positions {
        match at.get(&key(p)) {
            None => return None,
            Some(c) if c.len() > 1 => ambiguous += 1,
            Some(_) => {}
        }
    }
    // In order if possible: the next candidate after the previous match.
    let mut map = Vec::with_capacity(output.positions.len());
    let mut last: Option<u32> = None;
    for p in &output.positions {
        let c = &at[&key(p)];
        let next = c.iter().copied().find(|&i| last.is_none_or(|l| i > l));
        match next {
            Some(i) => {
                map.push(i);
                last = Some(i);
            }
            None => {
                map.clear();
                break;
            }
        }
    }
    if map.len() != output.positions.len() {
        map = output.positions.iter().map(|p| at[&key(p)][0]).collect();
    }
    let triangles = output
        .triangles
        .iter()
        .map(|t| t.map(|i| map.get(i as usize).copied().unwrap_or(u32::MAX)))
        .collect();
    Some((
        MeshData {
            positions: input.positions.clone(),
            triangles,
        },
        ambiguous,
    ))
}

// ---------------------------------------------------------------------------------------------
// Polygons

/// Polygons with more corners than this are split as a fan from their first corner instead of
/// by ear clipping (which is cubic in the worst case).
pub const MAX_EAR_CLIPPED: usize = 1024;

/// Splits a polygon (vertex indices in order, at least three) into `n - 2` triangles wound as
/// the polygon is, by ear clipping in the plane the polygon faces most (Newell's normal), so
/// concave polygons come out right; a polygon with no area or that crosses itself is still split
/// into `n - 2` triangles (the best ear there is, then any), never refused. Past
/// [`MAX_EAR_CLIPPED`] corners: a fan.
pub fn triangulate(positions: &[[f32; 3]], poly: &[u32]) -> Vec<[u32; 3]> {
    let n = poly.len();
    if n < 3 {
        return Vec::new();
    }
    if n == 3 {
        return vec![[poly[0], poly[1], poly[2]]];
    }
    if n > MAX_EAR_CLIPPED {
        // Ear clipping is cubic in the worst case; such faces are not seen in real files.
        return (1..n - 1)
            .map(|k| [poly[0], poly[k], poly[k + 1]])
            .collect();
    }
    let p3 = |i: u32| -> [f64; 3] {
        positions
            .get(i as usize)
            .map_or([0.0; 3], |p| p.map(f64::from))
    };
    // Newell's normal.
    let mut nrm = [0.0f64; 3];
    for k in 0..n {
        let (a, b) = (p3(poly[k]), p3(poly[(k + 1) % n]));
        nrm[0] += (a[1] - b[1]) * (a[2] + b[2]);
        nrm[1] += (a[2] - b[2]) * (a[0] + b[0]);
        nrm[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    let axis = (0..3)
        .max_by(|&a, &b| nrm[a].abs().total_cmp(&nrm[b].abs()))
        .unwrap_or(2);
    // (u, v) axes cyclic after the dropped one: a polygon facing +axis runs counter-clockwise.
    let (ua, va) = ((axis + 1) % 3, (axis + 2) % 3);
    let sign = if nrm[axis] < 0.0 { -1.0 } else { 1.0 };
    let pt: Vec<[f64; 2]> = poly
        .iter()
        .map(|&i| {
            let p = p3(i);
            [p[ua], sign * p[va]]
        })
        .collect();
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut rest: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    // The first ear tried is corners 0, 1, 2: a convex quad a b c d becomes a b c, a c d.
    let mut start = 1;
    while rest.len() > 3 {
        let m = rest.len();
        let mut ear = None;
        let mut convex_any = None;
        for s in 0..m {
            let k = (start + s) % m;
            let (a, b, c) = (rest[(k + m - 1) % m], rest[k], rest[(k + 1) % m]);
            if cross(pt[a], pt[b], pt[c]) <= 0.0 {
                continue; // reflex or flat: not an ear
            }
            convex_any.get_or_insert(k);
            // No other corner inside or on the triangle (corners at the same place as one of
            // a, b, c excepted: a polygon may touch itself there).
            let blocked = rest.iter().any(|&q| {
                if q == a || q == b || q == c || [a, b, c].iter().any(|&x| pt[x] == pt[q]) {
                    return false;
                }
                cross(pt[a], pt[b], pt[q]) >= 0.0
                    && cross(pt[b], pt[c], pt[q]) >= 0.0
                    && cross(pt[c], pt[a], pt[q]) >= 0.0
            });
            if !blocked {
                ear = Some(k);
                break;
            }
        }
        let k = ear.or(convex_any).unwrap_or(start % m);
        let (a, b, c) = (rest[(k + m - 1) % m], rest[k], rest[(k + 1) % m]);
        out.push([poly[a], poly[b], poly[c]]);
        rest.remove(k);
        start = k % rest.len();
    }
    out.push([poly[rest[0]], poly[rest[1]], poly[rest[2]]]);
    out
}

/// Which of `positions` a triangle or a polygon uses (indices past the end are ignored: they
/// are reported apart).
fn used_vertices(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    polygons: &[(usize, Vec<u32>)],
) -> Vec<bool> {
    let mut used = vec![false; positions.len()];
    let corners = triangles
        .iter()
        .flatten()
        .chain(polygons.iter().flat_map(|(_, p)| p));
    for &i in corners {
        if let Some(u) = used.get_mut(i as usize) {
            *u = true;
        }
    }
    used
}

/// Writes the simplified primitives (`results[k]` for `file.primitives[k]`, in the input's
/// vertex numbering) to a file that is not glTF, in `format`, and prints on stderr one line
/// naming what the format cannot hold and is not written. OBJ carries each primitive's
/// texture coordinates and normals ([`crate::io::objattr::from_gltf`]); PLY and STL, and OBJ
/// with `keep_numbering`, get positions and triangles ([`gltf::geometry`]'s numbering, kept or
/// compacted). Returns what was written per vertex, e.g. "POSITION, NORMAL, TEXCOORD_0".
pub fn save_gltf_as(
    path: &Path,
    format: Format,
    file: &gltf::GltfFile,
    results: &[gltf::Triangles],
    keep_numbering: bool,
) -> anyhow::Result<String> {
    if results.len() != file.primitives.len() {
        anyhow::bail!("{}: one result per primitive", path.display());
    }
    let (written, not_written, what) = if format == Format::Obj && !keep_numbering {
        let (obj, not_written) = crate::io::objattr::from_gltf(file);
        let text = crate::io::objattr::write(&obj, results);
        std::fs::write(path, text)
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
        let mut written: Vec<&str> = vec!["POSITION"];
        if !obj.vn_text.is_empty() {
            written.push("NORMAL");
        }
        if !obj.vt_text.is_empty() {
            written.push("texture coordinates");
        }
        (
            written.join(", "),
            not_written,
            "OBJ holds positions, one set of texture coordinates and normals",
        )
    } else {
        let (all, notes) = gltf::geometry(file);
        let mut mesh = crate::io::MeshData {
            positions: all.positions,
            triangles: Vec::new(),
        };
        let mut base = 0u32;
        for (p, tris) in file.primitives.iter().zip(results) {
            mesh.triangles
                .extend(tris.iter().map(|t| t.map(|i| base + i)));
            base += p.positions.len() as u32;
        }
        if !keep_numbering {
            mesh = crate::io::compact(&mesh).0;
        }
        crate::io::save_as(path, format, &mesh)?;
        let mut not_written = notes.dropped;
        let inst = gltf::Instancing::of(file);
        if inst.transformed || !inst.meshes.is_empty() {
            not_written.push("the scene's nodes (each primitive once, untransformed)".into());
        }
        let what = match format {
            Format::Obj => "OBJ with the input's numbering holds positions only",
            Format::Ply => "PLY is written with positions and triangles only",
            Format::Stl => "STL holds positions and triangles only",
        };
        ("POSITION".to_string(), not_written, what)
    };
    if !not_written.is_empty() {
        eprintln!(
            "note: {}: {what}; not written: {}",
            path.display(),
            not_written.join(", ")
        );
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp() -> tempfile::TempDir {
        tempfile::tempdir().unwrap()
    }

    fn tetra() -> MeshData {
        MeshData {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.1, 0.2, 1e-7], // unreferenced
            ],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        }
    }

    fn err_of(path: &Path) -> String {
        format!("{:#}", load(path).unwrap_err())
    }

    #[test]
    fn obj_round_trip_keeps_numbering_and_values() {
        let d = tmp();
        let p = d.path().join("t.obj");
        let mut m = tetra();
        m.positions[1] = [0.1, f32::MIN, f32::MIN_POSITIVE];
        save(&p, &m).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.starts_with("v 0 0 0\nv 0.1 -340282350000000000000000000000000000000 "));
        assert!(text.contains("\nf 1 3 2\n"));
        assert_eq!(load(&p).unwrap(), m);
    }

    #[test]
    fn obj_reader_details() {
        let d = tmp();
        let p = d.path().join("a.OBJ");
        std::fs::write(
            &p,
            "# comment\nmtllib x.mtl\nv 0 0 0\nv 1 0 0 1.0\nvt 0 0\nv 0 1 0\nvn 0 0 1\n\
             o thing\nv 5 5 5\ng grp\nf 1/1/1 2//1 3\nf -4 -2 -3 # relative\n",
        )
        .unwrap();
        let m = load(&p).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 1]]);
    }

    #[test]
    fn obj_errors_name_file_and_line() {
        let d = tmp();
        let p = d.path().join("q.obj");
        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2\n").unwrap();
        let e = err_of(&p);
        assert!(
            e.contains("q.obj") && e.contains("line 5") && e.contains("at least 3"),
            "{e}"
        );

        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap();
        let e = err_of(&p);
        assert!(e.contains("line 3") && e.contains("vertex 3"), "{e}");

        std::fs::write(&p, "v 0 0 0\nv 1 0 x\n").unwrap();
        assert!(err_of(&p).contains("line 2"));
        std::fs::write(&p, "v 0 0 0\n").unwrap();
        assert!(err_of(&p).contains("no triangles"));
        std::fs::write(&p, b"v 0 0 0\n\xff\xfe\n").unwrap();
        assert!(err_of(&p).contains("line 2"));
        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 0 0 nan\nf 1 2 3\n").unwrap();
        let e = err_of(&p);
        assert!(e.contains("non-finite") && e.contains("line 3"), "{e}");
        assert!(err_of(&d.path().join("missing.obj")).contains("missing.obj"));
        assert!(err_of(&d.path().join("x.off")).contains("unknown mesh format"));
    }

    #[test]
    fn truncated_obj_reports_last_line() {
        let d = tmp();
        let p = d.path().join("t.obj");
        save(&p, &tetra()).unwrap();
        let full = std::fs::read(&p).unwrap();
        // Cut inside the last face line ("f 1 4 3\n" -> "f 1 4").
        std::fs::write(&p, &full[..full.len() - 3]).unwrap();
        let e = err_of(&p);
        assert!(e.contains("t.obj") && e.contains("line 9"), "{e}");
    }

    #[test]
    fn ply_binary_round_trip_and_truncation() {
        let d = tmp();
        let p = d.path().join("t.ply");
        let m = tetra();
        save(&p, &m).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        assert!(bytes.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
        assert_eq!(load(&p).unwrap(), m);
        for cut in [1, 7, 20] {
            std::fs::write(&p, &bytes[..bytes.len() - cut]).unwrap();
            let e = err_of(&p);
            assert!(e.contains("t.ply") && e.contains("byte offset"), "{e}");
        }
    }

    #[test]
    fn ply_ascii_and_errors() {
        let d = tmp();
        let p = d.path().join("a.ply");
        let head = "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty float x\n\
                    property float y\nproperty float z\nproperty float confidence\n\
                    element face 2\nproperty list uchar int vertex_indices\nend_header\n";
        let body = "0 0 0 1\n1 0 0 1\n0 1 0 1\n1 1 0 1\n3 0 1 2\n3 1 3 2\n";
        std::fs::write(&p, format!("{head}{body}")).unwrap();
        let m = load(&p).unwrap();
        assert_eq!(m.positions[3], [1.0, 1.0, 0.0]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [1, 3, 2]]);

        // Truncated inside the last face.
        std::fs::write(&p, format!("{head}{}", &body[..body.len() - 4])).unwrap();
        let e = err_of(&p);
        assert!(
            e.contains("a.ply") && e.to_lowercase().contains("line"),
            "{e}"
        );
        // Truncated before the last face line.
        std::fs::write(&p, format!("{head}{}", &body[..body.len() - 8])).unwrap();
        let e = err_of(&p);
        assert!(e.contains("a.ply"), "{e}");
        // Truncated in the header.
        std::fs::write(&p, &head[..40]).unwrap();
        let e = err_of(&p);
        assert!(e.contains("a.ply") && e.contains("header"), "{e}");
        // A quad.
        std::fs::write(
            &p,
            format!(
                "{}4 0 1 3 2\n3 1 3 2\n",
                &format!("{head}{body}")[..head.len() + 32]
            ),
        )
        .unwrap();
        let (m, notes) = load_with_notes(&p).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 3], [0, 3, 2], [1, 3, 2]]);
        assert_eq!(
            (notes.polygons_split, notes.triangles_from_polygons),
            (1, 2)
        );
        assert_eq!(notes.dropped, vec!["vertex properties confidence"]);
    }

    /// Twice the signed area of a triangle in the z = 0 plane.
    fn area2(p: &[[f32; 3]], t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|i| p[i as usize].map(f64::from));
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    }

    #[test]
    fn concave_polygons_are_ear_clipped() {
        // An arrow (concave at vertex 4) and a comb with three teeth, counter-clockwise.
        let arrow: Vec<[f32; 3]> = vec![
            [0., 0., 0.],
            [4., 0., 0.],
            [4., 4., 0.],
            [2., 4., 0.],
            [2., 1., 0.], // the notch
            [0., 4., 0.],
        ];
        let comb: Vec<[f32; 3]> = vec![
            [0., 0., 0.],
            [5., 0., 0.],
            [5., 3., 0.],
            [4., 3., 0.],
            [4., 1., 0.],
            [3., 1., 0.],
            [3., 3., 0.],
            [2., 3., 0.],
            [2., 1., 0.],
            [1., 1., 0.],
            [1., 3., 0.],
            [0., 3., 0.],
        ];
        for (p, area) in [(arrow, 13.0), (comb, 11.0)] {
            let n = p.len() as u32;
            let poly: Vec<u32> = (0..n).collect();
            for flip in [false, true] {
                // The same polygon wound the other way must give the mirrored triangles.
                let poly: Vec<u32> = if flip {
                    poly.iter().rev().copied().collect()
                } else {
                    poly.clone()
                };
                let tris = triangulate(&p, &poly);
                assert_eq!(tris.len(), n as usize - 2);
                let mut sum = 0.0;
                for &t in &tris {
                    let a = area2(&p, t) * if flip { -1.0 } else { 1.0 };
                    assert!(a > 0.0, "{t:?} is wound against the polygon or flat");
                    sum += a / 2.0;
                }
                assert!(
                    (sum - area).abs() < 1e-9,
                    "{sum} != {area}: triangles overlap"
                );
            }
            // Tilted into 3D (facing mostly -x), still n - 2 triangles covering the area.
            let q: Vec<[f32; 3]> = p.iter().map(|v| [-0.2 * v[0], v[1], v[0]]).collect();
            assert_eq!(
                triangulate(&q, &(0..n).collect::<Vec<_>>()).len(),
                n as usize - 2
            );
        }
        // Degenerate: all corners on a line; still n - 2 triangles, no panic.
        let line: Vec<[f32; 3]> = (0..5).map(|i| [i as f32, 0., 0.]).collect();
        assert_eq!(triangulate(&line, &[0, 1, 2, 3, 4]).len(), 3);
    }

    #[test]
    fn obj_polygons_are_split_and_attributes_noted() {
        let d = tmp();
        let p = d.path().join("poly.obj");
        std::fs::write(
            &p,
            "mtllib m.mtl\nv 0 0 0\nv 4 0 0\nv 4 4 0\nv 2 4 0\nv 2 1 0\nv 0 4 0\nvt 0 0\n\
             vn 0 0 1\nvn 0 0 1\nusemtl red\nf 1 2 3\nf 1/1/1 2/1/1 3/1/2 4/1/2 5/1/2 6/1/2\n\
             f 1 3 6\n",
        )
        .unwrap();
        let (m, notes) = load_with_notes(&p).unwrap();
        assert_eq!(m.triangles.len(), 1 + 4 + 1);
        // In file order: the hexagon's four triangles between the two triangles.
        assert_eq!(m.triangles[0], [0, 1, 2]);
        assert_eq!(m.triangles[5], [0, 2, 5]);
        assert_eq!(
            (notes.polygons_split, notes.triangles_from_polygons),
            (1, 4)
        );
        let lines = notes.lines("poly.obj");
        assert!(lines[0].contains("1 polygon(s)") && lines[0].contains("4 triangles"));
        assert!(
            lines[1].contains("1 texture coordinates (vt)")
                && lines[1].contains("2 normals (vn)")
                && lines[1].contains("`mtllib`, `usemtl`"),
            "{lines:?}"
        );
        // Only positions and triangles: nothing to say.
        save(&p, &tetra()).unwrap();
        assert!(load_with_notes(&p).unwrap().1.lines("x").is_empty());
    }

    #[test]
    fn stl_is_written_and_reads_back() {
        let d = tmp();
        let p = d.path().join("t.stl");
        let m = tetra();
        save(&p, &m).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        assert_eq!(bytes.len(), 84 + 50 * 4);
        let back = load(&p).unwrap();
        assert_eq!(expand(&back), stl_tris());
        // Facet normal of [0, 2, 1] (z = 0 plane, wound clockwise seen from +z): -z.
        let n: Vec<f32> = (0..3)
            .map(|k| f32::from_le_bytes(bytes[84 + 4 * k..88 + 4 * k].try_into().unwrap()))
            .collect();
        assert_eq!(n, vec![0.0, 0.0, -1.0]);
        assert_eq!(sniff(&bytes), Format::Stl);
    }

    #[test]
    fn formats_are_sniffed_from_bytes() {
        assert_eq!(sniff(b"ply\nformat ascii 1.0\n"), Format::Ply);
        assert_eq!(sniff(b"solid x\nfacet normal 0 0 1\n"), Format::Stl);
        assert_eq!(sniff(b"v 0 0 0\nf 1 1 1\n"), Format::Obj);
        assert_eq!(sniff(b"solid_name.obj\nv 0 0 0\n"), Format::Obj);
    }

    #[test]
    fn compact_drops_unreferenced_vertices_in_order() {
        let m = tetra();
        let (c, old) = compact(&m);
        assert_eq!(old, vec![0, 1, 2, 3]);
        assert_eq!(c.positions, m.positions[..4].to_vec());
        assert_eq!(c.triangles, m.triangles);
        let cut = MeshData {
            positions: m.positions.clone(),
            triangles: vec![[1, 2, 3]],
        };
        let (c, old) = compact(&cut);
        assert_eq!(old, vec![1, 2, 3]);
        assert_eq!(c.triangles, vec![[0, 1, 2]]);
        // ... and the check maps it back.
        let (r, twins) = renumber_onto(&m, &c).unwrap();
        assert_eq!((r.triangles, twins), (vec![[1, 2, 3]], 0));
        // A vertex the input does not have: no match.
        let mut bad = c.clone();
        bad.positions[0] = [9.0, 9.0, 9.0];
        assert!(renumber_onto(&m, &bad).is_none());
    }

    #[test]
    fn output_paths_are_checked_before_work() {
        let d = tmp();
        assert_eq!(
            check_writable(&d.path().join("a.stl"), None).unwrap(),
            Format::Stl
        );
        assert!(!d.path().join("a.stl").exists(), "the probe leaves nothing");
        let e = format!(
            "{:#}",
            check_writable(&d.path().join("a.off"), None).unwrap_err()
        );
        assert!(e.contains("unknown mesh format"), "{e}");
        let e = format!(
            "{:#}",
            check_writable(&d.path().join("no/such/dir/a.obj"), None).unwrap_err()
        );
        assert!(e.contains("cannot create"), "{e}");
        let e = format!(
            "{:#}",
            check_writable(d.path(), Some(Format::Obj)).unwrap_err()
        );
        assert!(e.contains("directory"), "{e}");
        // An existing file is not truncated by the check.
        let p = d.path().join("keep.obj");
        std::fs::write(&p, "v 0 0 0\n").unwrap();
        check_writable(&p, None).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "v 0 0 0\n");
        assert_eq!(check_writable(Path::new("-"), None).unwrap(), Format::Obj);
        assert_eq!(
            check_writable(Path::new("-"), Some(Format::Ply)).unwrap(),
            Format::Ply
        );
    }

    /// Element counts the file cannot hold are refused before the payload is read: found by
    /// the `ply` fuzz target (`fuzz/regressions/ply-huge-element-count`), which ran out of
    /// memory before failing, because an element without properties takes no bytes to read.
    #[test]
    fn ply_element_count_larger_than_the_file_is_refused_at_once() {
        let found = include_bytes!("../../fuzz/regressions/ply-huge-element-count");
        let e = format!("{:#}", parse_bytes(found, "ply").unwrap_err());
        assert!(
            e.contains("41111111111110") && e.contains("truncated"),
            "{e}"
        );

        let end = "property float x\nproperty float y\nproperty float z\n\
                   element face 0\nproperty list uchar int vertex_indices\nend_header\n";
        // ASCII: at least a line per element.
        let ascii = format!("ply\nformat ascii 1.0\nelement vertex 4000000000\n{end}0 0 0\n");
        let e = format!("{:#}", parse_bytes(ascii.as_bytes(), "ply").unwrap_err());
        assert!(
            e.contains("4000000000 `vertex`") && e.contains("6 bytes"),
            "{e}"
        );
        // Binary: 12 bytes per vertex, so 3 vertices do not fit in 24 bytes...
        let bin = |n: usize, body: usize| {
            let mut b = format!("ply\nformat binary_little_endian 1.0\nelement vertex {n}\n{end}")
                .into_bytes();
            b.resize(b.len() + body, 0);
            parse_bytes(&b, "ply").map_err(|e| format!("{e:#}"))
        };
        let e = bin(3, 24).unwrap_err();
        assert!(e.contains("at least 36 bytes"), "{e}");
        // ...but 2 do: the payload is read, and the file fails later, for having no triangles.
        let e = bin(2, 24).unwrap_err();
        assert!(e.contains("no triangles"), "{e}");
        // An element without properties counts one byte each.
        let mut b = b"ply\nformat binary_big_endian 1.0\nelement junk 99999999999\n".to_vec();
        b.extend_from_slice(
            end.replace("element face 0\n", "element vertex 0\n")
                .as_bytes(),
        );
        let e = format!("{:#}", parse_bytes(&b, "ply").unwrap_err());
        assert!(e.contains("99999999999 `junk`"), "{e}");
    }

    fn stl_binary(header: &[u8], tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = vec![b' '; 80];
        b[..header.len()].copy_from_slice(header);
        b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for v in t {
                for c in v {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    }

    fn stl_tris() -> Vec<[[f32; 3]; 3]> {
        let m = tetra();
        m.triangles
            .iter()
            .map(|t| t.map(|i| m.positions[i as usize]))
            .collect()
    }

    #[test]
    fn stl_binary_with_solid_header_is_welded() {
        let d = tmp();
        let p = d.path().join("s.stl");
        // The header starts like an ascii file: "solid plate\n".
        std::fs::write(&p, stl_binary(b"solid plate\nfacet normal", &stl_tris())).unwrap();
        let m = load(&p).unwrap();
        // Welded in order of first appearance: tetra's first triangle is [0, 2, 1].
        let t = tetra();
        let p = &t.positions;
        assert_eq!(m.positions, vec![p[0], p[2], p[1], p[3]]);
        assert_eq!(
            m.triangles,
            vec![[0, 1, 2], [0, 2, 3], [2, 1, 3], [0, 3, 1]]
        );
        assert_eq!(expand(&m), stl_tris());
    }

    fn expand(m: &MeshData) -> Vec<[[f32; 3]; 3]> {
        m.triangles
            .iter()
            .map(|t| t.map(|i| m.positions[i as usize]))
            .collect()
    }

    #[test]
    fn stl_binary_truncated() {
        let d = tmp();
        let p = d.path().join("s.stl");
        let b = stl_binary(b"solid x", &stl_tris());
        std::fs::write(&p, &b[..b.len() - 10]).unwrap();
        let e = err_of(&p);
        assert!(e.contains("s.stl") && e.contains("byte offset 234"), "{e}");
        // 50 bytes of "solid x" and blanks is ascii as far as anyone can tell.
        std::fs::write(&p, &b[..50]).unwrap();
        let e = err_of(&p);
        assert!(e.contains("s.stl") && e.contains("line 1"), "{e}");
        let b = stl_binary(b"binary", &stl_tris());
        std::fs::write(&p, &b[..50]).unwrap();
        let e = err_of(&p);
        assert!(e.contains("s.stl") && e.contains("84"), "{e}");
        std::fs::write(&p, &b[..b.len() - 60]).unwrap();
        let e = err_of(&p);
        assert!(e.contains("triangle 3 at byte offset 184"), "{e}");
    }

    #[test]
    fn stl_ascii_and_truncated() {
        let d = tmp();
        let p = d.path().join("a.stl");
        let mut s = String::from("solid t\n");
        for t in stl_tris() {
            s += "  facet normal 0 0 0\n    outer loop\n";
            for v in t {
                s += &format!("      vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            s += "    endloop\n  endfacet\n";
        }
        s += "endsolid t\n";
        std::fs::write(&p, &s).unwrap();
        let m = load(&p).unwrap();
        assert_eq!(expand(&m), stl_tris());
        assert_eq!(m.positions.len(), 4);
        // Cut inside the third facet's second vertex line.
        let cut = s.match_indices("vertex").nth(7).unwrap().0 + 9;
        std::fs::write(&p, &s[..cut]).unwrap();
        let e = err_of(&p);
        assert!(
            e.contains("a.stl") && e.contains("facet 3") && e.contains("line 16"),
            "{e}"
        );
    }

    #[test]
    fn every_truncation_is_an_error_not_a_panic() {
        let d = tmp();
        let m = tetra();
        let mut files = Vec::new();
        for name in ["t.obj", "t.ply"] {
            let p = d.path().join(name);
            save(&p, &m).unwrap();
            files.push((name, std::fs::read(&p).unwrap()));
        }
        files.push(("b.stl", stl_binary(b"solid t", &stl_tris())));
        let mut ascii = String::from("solid t\n");
        for t in stl_tris() {
            ascii += "facet normal 0 0 0\nouter loop\n";
            for v in t {
                ascii += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            ascii += "endloop\nendfacet\n";
        }
        files.push(("a.stl", ascii.into_bytes()));
        for (name, bytes) in files {
            let p = d.path().join(name);
            for len in 0..bytes.len() {
                std::fs::write(&p, &bytes[..len]).unwrap();
                // Text formats may parse a prefix that ends on a line break; binary ones never.
                if let Err(e) = load(&p) {
                    assert!(format!("{e:#}").contains(name));
                } else {
                    assert!(name.ends_with(".obj") || name == "a.stl", "{name} {len}");
                }
            }
        }
    }

    #[test]
    fn shared_meshes_match_tobj_geometry() {
        let dir = &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures");
        for name in ["cow.obj", "stanford_bunny.obj"] {
            let p = dir.join(name);
            let m = load(&p).unwrap();
            let (models, _) = tobj::load_obj(
                &p,
                &tobj::LoadOptions {
                    triangulate: false,
                    single_index: false,
                    ..Default::default()
                },
            )
            .unwrap();
            let t = &models[0].mesh;
            assert_eq!(t.indices.len(), m.triangles.len() * 3);
            for (k, tri) in m.triangles.iter().enumerate() {
                for (c, &v) in tri.iter().enumerate() {
                    let ours = m.positions[v as usize];
                    let j = t.indices[3 * k + c] as usize;
                    assert_eq!(
                        ours,
                        [
                            t.positions[3 * j],
                            t.positions[3 * j + 1],
                            t.positions[3 * j + 2]
                        ]
                    );
                }
            }
            if name == "stanford_bunny.obj" {
                assert_eq!(m.positions.len(), 35_947);
                assert_eq!(m.triangles.len(), 69_451);
            }
        }
    }
}

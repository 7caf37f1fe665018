//! Mesh files: OBJ, PLY (ascii and binary) and STL (ascii and binary) in, OBJ and binary PLY out.
//!
//! * **OBJ**: only `v` and `f` lines matter (`vt`, `vn`, `o`, `g`, `s`, `usemtl`, `l`, `p`, ...
//!   are ignored). Vertices keep the file's numbering exactly, unreferenced ones included; face
//!   corners may be written `a`, `a/b`, `a//c` or `a/b/c` and may be negative (relative).
//!   Faces that are not triangles are rejected. This is a small reader of our own: `tobj`
//!   always renumbers vertices in order of first use and drops unreferenced ones (checked in
//!   tobj 4.0.5, `add_vertex`/`add_vertex_multi_index`), so it cannot keep the file's
//!   numbering; `tobj` is used in the tests as an independent cross-check of the geometry.
//! * **PLY**: via `ply-rs-bw`; element `vertex` (`x`, `y`, `z`, any scalar type) and element
//!   `face` (list `vertex_indices` or `vertex_index`, triangles only).
//! * **STL**: via `stl_io`; corners are welded by bit-exact `f32` position, vertices numbered
//!   by first appearance. A file is binary when its size is exactly `84 + 50 n` bytes with `n`
//!   the triangle count at offset 80, even if its header starts with `solid` (`stl_io` 0.11
//!   alone would take such a file for ascii and fail).
//!
//! Every error names the file and, where it can, the line (text) or byte offset (binary).
//! A file without any triangle is an error, and so is a non-finite coordinate or a face index
//! past the last vertex.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::{BufWriter, Cursor, Write};
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};

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

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Obj,
    Ply,
    Stl,
}

fn format_of(path: &Path) -> Result<Format> {
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

/// Loads a triangle mesh, choosing the format by extension (`.obj`, `.ply`, `.stl`, any case).
pub fn load(path: impl AsRef<Path>) -> Result<MeshData> {
    let path = path.as_ref();
    let format = format_of(path)?;
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let name = path.display().to_string();
    let mesh = match format {
        Format::Obj => parse_obj(&bytes),
        Format::Ply => parse_ply(&bytes),
        Format::Stl => parse_stl(&bytes),
    }
    .map_err(|e| anyhow!("{name}: {e}"))?;
    validate(&mesh).map_err(|e| anyhow!("{name}: {e}"))?;
    Ok(mesh)
}

/// Parses a mesh from memory, the format given by `ext` (`obj`, `ply` or `stl`, any case, no
/// dot), with the checks of [`load`]. Errors carry no file name. Used by the fuzz targets.
pub fn parse_bytes(bytes: &[u8], ext: &str) -> Result<MeshData> {
    let format = match ext.to_ascii_lowercase().as_str() {
        "obj" => Format::Obj,
        "ply" => Format::Ply,
        "stl" => Format::Stl,
        _ => bail!("unknown mesh format {ext:?} (expected obj, ply or stl)"),
    };
    let mesh = match format {
        Format::Obj => parse_obj(bytes),
        Format::Ply => parse_ply(bytes),
        Format::Stl => parse_stl(bytes),
    }
    .map_err(|e| anyhow!(e))?;
    validate(&mesh).map_err(|e| anyhow!(e))?;
    Ok(mesh)
}

/// Checks what every loader promises: some triangles, indices in range, finite coordinates.
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
    if let Some(v) = mesh
        .positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(format!("vertex {} has a non-finite coordinate", v + 1));
    }
    Ok(())
}

/// Saves a mesh, choosing the format by extension: `.obj` (text, 1-based, shortest round-trip
/// coordinates) or `.ply` (binary little endian, `float` x y z, `list uchar int
/// vertex_indices`). All positions are written, so the vertex numbering is kept.
pub fn save(path: impl AsRef<Path>, mesh: &MeshData) -> Result<()> {
    let path = path.as_ref();
    let format = format_of(path)?;
    let bytes = match format {
        Format::Obj => obj_bytes(mesh),
        Format::Ply => ply_bytes(mesh).map_err(|e| anyhow!("{}: {e}", path.display()))?,
        Format::Stl => bail!("{}: writing STL is not supported", path.display()),
    };
    let file = std::fs::File::create(path)
        .with_context(|| format!("{}: cannot create", path.display()))?;
    let mut w = BufWriter::new(file);
    w.write_all(&bytes)
        .and_then(|()| w.flush())
        .with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// OBJ

fn parse_obj(bytes: &[u8]) -> std::result::Result<MeshData, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let at = e.valid_up_to();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        format!("line {line} (byte offset {at}): not valid UTF-8 text")
    })?;
    let mut mesh = MeshData::default();
    // Largest vertex index referenced by a face and the line it is on, checked at the end
    // (an OBJ face may refer to a vertex defined later).
    let mut max_ref: Option<(usize, usize)> = None;
    for (no, raw) in text.lines().enumerate() {
        let line_no = no + 1;
        let line = raw.split('#').next().unwrap_or("");
        let mut tokens = line.split_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let mut p = [0f32; 3];
                for (k, c) in p.iter_mut().enumerate() {
                    let tok = tokens.next().ok_or_else(|| {
                        format!(
                            "line {line_no}: vertex has {k} coordinate(s), expected 3: {:?}",
                            raw.trim()
                        )
                    })?;
                    *c = tok
                        .parse::<f32>()
                        .map_err(|_| format!("line {line_no}: bad vertex coordinate {tok:?}"))?;
                    if !c.is_finite() {
                        return Err(format!(
                            "line {line_no}: non-finite vertex coordinate {tok:?}"
                        ));
                    }
                }
                mesh.positions.push(p);
            }
            "f" => {
                let corners: Vec<&str> = tokens.collect();
                if corners.len() != 3 {
                    return Err(format!(
                        "line {line_no}: face with {} corner(s); only triangles are supported",
                        corners.len()
                    ));
                }
                let mut tri = [0u32; 3];
                for (slot, tok) in tri.iter_mut().zip(&corners) {
                    let idx = tok.split('/').next().unwrap_or("");
                    let i: i64 = idx
                        .parse()
                        .map_err(|_| format!("line {line_no}: bad face index {tok:?}"))?;
                    let n = mesh.positions.len() as i64;
                    let zero_based = match i {
                        0 => return Err(format!("line {line_no}: face index 0 (OBJ is 1-based)")),
                        i if i > 0 => i - 1,
                        i => n + i, // relative to the vertices read so far
                    };
                    if zero_based < 0 {
                        return Err(format!(
                            "line {line_no}: relative face index {i} points before the first vertex"
                        ));
                    }
                    let z = u32::try_from(zero_based)
                        .map_err(|_| format!("line {line_no}: face index {i} too large"))?;
                    if max_ref.is_none_or(|(m, _)| z as usize > m) {
                        max_ref = Some((z as usize, line_no));
                    }
                    *slot = z;
                }
                mesh.triangles.push(tri);
            }
            _ => {}
        }
    }
    if let Some((m, line_no)) = max_ref {
        if m >= mesh.positions.len() {
            return Err(format!(
                "line {line_no}: face refers to vertex {} but the file has only {} vertices",
                m + 1,
                mesh.positions.len()
            ));
        }
    }
    Ok(mesh)
}

fn obj_bytes(mesh: &MeshData) -> Vec<u8> {
    let mut s = String::with_capacity(mesh.positions.len() * 32 + mesh.triangles.len() * 24);
    for p in &mesh.positions {
        // `Display` for f32 prints the shortest decimal that round-trips, never in exponent form.
        let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
    }
    for t in &mesh.triangles {
        let _ = writeln!(
            s,
            "f {} {} {}",
            u64::from(t[0]) + 1,
            u64::from(t[1]) + 1,
            u64::from(t[2]) + 1
        );
    }
    s.into_bytes()
}

// ---------------------------------------------------------------------------------------------
// PLY

/// Bytes of one binary PLY scalar.
fn scalar_bytes(t: &ply_rs_bw::ply::ScalarType) -> usize {
    use ply_rs_bw::ply::ScalarType::*;
    match t {
        Char | UChar => 1,
        Short | UShort => 2,
        Int | UInt | Float => 4,
        Double => 8,
    }
}

fn parse_ply(bytes: &[u8]) -> std::result::Result<MeshData, String> {
    use ply_rs_bw::parser::{Parser, Reader};
    use ply_rs_bw::ply::{DefaultElement, Encoding};

    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| match e.line() {
            Some(_) => format!("PLY header: {e}"),
            None => format!("PLY header (line {}): {e}", reader.line()),
        })?;
    // A header can declare any element count; the payload reader then keeps adding elements
    // (fuzzing found one that used 2 GB) before it notices the file is short. Every element
    // takes at least one byte (an ASCII line; a binary scalar or list length), most take more,
    // so a count the rest of the file cannot hold is refused here as a truncated file.
    let rest = bytes
        .len()
        .saturating_sub(reader.get_ref().position() as usize);
    for e in header.elements.values() {
        let each = match header.encoding {
            Encoding::Ascii => 1,
            _ => e
                .properties
                .values()
                .map(|p| match &p.data_type {
                    ply_rs_bw::ply::PropertyType::Scalar(t) => scalar_bytes(t),
                    ply_rs_bw::ply::PropertyType::List(n, _) => scalar_bytes(n),
                })
                .sum::<usize>()
                .max(1),
        };
        if e.count.saturating_mul(each) > rest {
            return Err(format!(
                "PLY header declares {} `{}` elements, at least {} bytes, but only {rest} bytes \
                 follow the header (truncated file?)",
                e.count,
                e.name,
                e.count.saturating_mul(each)
            ));
        }
    }
    let payload = parser.read_payload(&mut reader, &header).map_err(|e| {
        let offset = reader.get_ref().position();
        match header.encoding {
            Encoding::Ascii => match e.line() {
                Some(_) => format!("PLY ascii data: {e}"),
                None => format!("PLY ascii data (line {}): {e}", reader.line()),
            },
            _ => format!(
                "PLY binary data near byte offset {offset} of {}: {e} (truncated file?)",
                bytes.len()
            ),
        }
    })?;

    let mut mesh = MeshData::default();
    let vertices = payload
        .get("vertex")
        .ok_or("PLY file has no `vertex` element")?;
    mesh.positions.reserve(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let mut p = [0f32; 3];
        for (c, key) in p.iter_mut().zip(["x", "y", "z"]) {
            *c = v
                .get(key)
                .and_then(|prop| prop.to_f32_lossy())
                .ok_or_else(|| format!("PLY vertex {i} has no scalar property `{key}`"))?;
        }
        mesh.positions.push(p);
    }
    let faces = payload
        .get("face")
        .ok_or("PLY file has no `face` element")?;
    mesh.triangles.reserve(faces.len());
    for (i, f) in faces.iter().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .ok_or_else(|| format!("PLY face {i} has no `vertex_indices` list"))?;
        let idx = list.to_u32_list().ok_or_else(|| {
            format!("PLY face {i}: indices are not a list of non-negative integers")
        })?;
        let tri: [u32; 3] = idx.as_slice().try_into().map_err(|_| {
            format!(
                "PLY face {i} has {} corners; only triangles are supported",
                idx.len()
            )
        })?;
        mesh.triangles.push(tri);
    }
    Ok(mesh)
}

fn ply_bytes(mesh: &MeshData) -> std::result::Result<Vec<u8>, String> {
    use ply_rs_bw::ply::{
        Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
        ScalarType,
    };
    use ply_rs_bw::writer::Writer;

    let mut ply = Ply::<DefaultElement>::new();
    ply.header.encoding = Encoding::BinaryLittleEndian;
    ply.header
        .comments
        .push("written by tinydecimate host-sim".into());
    let mut vdef = ElementDef::new("vertex".into());
    for k in ["x", "y", "z"] {
        vdef.properties.add(PropertyDef::new(
            k.into(),
            PropertyType::Scalar(ScalarType::Float),
        ));
    }
    ply.header.elements.add(vdef);
    let mut fdef = ElementDef::new("face".into());
    fdef.properties.add(PropertyDef::new(
        "vertex_indices".into(),
        PropertyType::List(ScalarType::UChar, ScalarType::Int),
    ));
    ply.header.elements.add(fdef);

    let vertices: Vec<DefaultElement> = mesh
        .positions
        .iter()
        .map(|p| {
            let mut e = DefaultElement::new();
            e.insert("x".into(), Property::Float(p[0]));
            e.insert("y".into(), Property::Float(p[1]));
            e.insert("z".into(), Property::Float(p[2]));
            e
        })
        .collect();
    let mut faces = Vec::with_capacity(mesh.triangles.len());
    for t in &mesh.triangles {
        let mut list = Vec::with_capacity(3);
        for &i in t {
            list.push(
                i32::try_from(i).map_err(|_| format!("vertex index {i} too large for PLY int"))?,
            );
        }
        let mut e = DefaultElement::new();
        e.insert("vertex_indices".into(), Property::ListInt(list));
        faces.push(e);
    }
    ply.payload.insert("vertex".into(), vertices);
    ply.payload.insert("face".into(), faces);
    let mut out = Vec::new();
    Writer::new()
        .write_ply(&mut out, &mut ply)
        .map_err(|e| format!("cannot encode PLY: {e}"))?;
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// STL

/// Whether `bytes` is a binary STL by its size: `84 + 50 n` with `n` at offset 80.
fn stl_size_matches_binary(bytes: &[u8]) -> bool {
    bytes
        .get(80..84)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize)
        .and_then(|n| n.checked_mul(50))
        .and_then(|s| s.checked_add(84))
        == Some(bytes.len())
}

fn parse_stl(bytes: &[u8]) -> std::result::Result<MeshData, String> {
    // Ascii: starts with "solid" and its first KiB is plain ASCII text (a binary file, even with
    // a "solid" header, has NUL or high bytes in its triangle count or floats).
    let head = &bytes[..bytes.len().min(1024)];
    let looks_ascii = bytes.trim_ascii_start().starts_with(b"solid")
        && head.iter().all(|&b| b != 0 && b.is_ascii());
    let binary = stl_size_matches_binary(bytes) || !looks_ascii;
    if binary {
        if bytes.len() < 84 {
            return Err(format!(
                "binary STL truncated: {} bytes, the header alone takes 84",
                bytes.len()
            ));
        }
        if !stl_size_matches_binary(bytes) {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
            let complete = (bytes.len() as u64 - 84) / 50;
            return Err(format!(
                "binary STL: header says {n} triangles ({} bytes) but the file has {} bytes; \
                 triangle {} at byte offset {} is {}",
                84 + 50 * n,
                bytes.len(),
                complete + 1,
                84 + 50 * complete,
                if complete < n {
                    "incomplete (truncated file?)"
                } else {
                    "followed by extra bytes"
                }
            ));
        }
    }
    // stl_io probes ascii by a first line starting with "solid "; a binary header may too, so
    // hand it a copy whose (ignored) header is blanked.
    let mut data = bytes.to_vec();
    if binary {
        data[..80].fill(0);
    }
    let mut cursor = Cursor::new(data);
    let iter = stl_io::create_stl_reader(&mut cursor).map_err(|e| format!("STL: {e}"))?;
    let mut mesh = MeshData::default();
    let mut welded: HashMap<[u32; 3], u32> = HashMap::new();
    for (k, t) in iter.enumerate() {
        let t = t.map_err(|e| {
            if binary {
                format!(
                    "binary STL triangle {} at byte offset {}: {e}",
                    k + 1,
                    84 + 50 * k
                )
            } else {
                let line = ascii_facet_line(bytes, k)
                    .map(|l| format!(" (from line {l})"))
                    .unwrap_or_default();
                format!("ascii STL facet {}{line}: {e}", k + 1)
            }
        })?;
        let mut tri = [0u32; 3];
        for (slot, v) in tri.iter_mut().zip(t.vertices.iter()) {
            let key = v.0.map(f32::to_bits);
            let next = u32::try_from(mesh.positions.len()).map_err(|_| "too many vertices")?;
            *slot = *welded.entry(key).or_insert_with(|| {
                mesh.positions.push(v.0);
                next
            });
        }
        mesh.triangles.push(tri);
    }
    Ok(mesh)
}

/// 1-based line on which the `k`-th (0-based) `facet` of an ascii STL starts, or the last
/// line if there are fewer facets.
fn ascii_facet_line(bytes: &[u8], k: usize) -> Option<usize> {
    let text = String::from_utf8_lossy(bytes);
    let mut seen = 0;
    let mut last = 0;
    for (no, line) in text.lines().enumerate() {
        last = no + 1;
        if line.split_whitespace().next() == Some("facet") {
            if seen == k {
                return Some(no + 1);
            }
            seen += 1;
        }
    }
    (last > 0).then_some(last)
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
        std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\n").unwrap();
        let e = err_of(&p);
        assert!(
            e.contains("q.obj") && e.contains("line 5") && e.contains("only triangles"),
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
        std::fs::write(&p, "v 0 0 nan\n").unwrap();
        assert!(err_of(&p).contains("non-finite"));
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
        let e = err_of(&p);
        assert!(e.contains("only triangles"), "{e}");
    }

    /// Element counts the file cannot hold are refused before the payload is read: found by
    /// the `ply` fuzz target (`fuzz/regressions/ply-huge-element-count`), which took 20 s and
    /// 6.8 GB before failing, because an element without properties takes no bytes to read.
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
        let dir = Path::new("/work/shared/meshes");
        for name in ["cow.obj", "stanford_bunny.obj"] {
            let p = dir.join(name);
            if !p.exists() {
                continue;
            }
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

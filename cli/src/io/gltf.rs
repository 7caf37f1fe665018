//! glTF 2.0 in and out (`.gltf` with its buffers, `.glb`): every triangle primitive is read
//! as its own mesh with all of its vertex attributes, simplified on its own, and written back
//! with only the vertices it still uses.
//!
//! * **Reading.** The GLB container (header, JSON chunk, BIN chunk) is split here with every
//!   length checked; the JSON is parsed and validated by the `gltf` crate (indices between
//!   objects, required fields). Buffers come from the BIN chunk, a `data:` URI (base64) or a
//!   file next to the `.gltf`. Accessors are read here, not by the crate: before anything is
//!   allocated, the last element's end (`byteOffset + stride·(count-1) + element size`) is
//!   checked against the buffer view, and the view against its buffer, so a claimed count
//!   never allocates more than the file holds. Primitives of mode TRIANGLES (indexed or not)
//!   are read; other modes (points, lines, strips, fans) are passed through untouched.
//! * **What is kept.** Every attribute of a primitive (POSITION, NORMAL, TANGENT, TEXCOORD_n,
//!   COLOR_n, JOINTS_n, WEIGHTS_n, custom `_NAME`s) and its morph targets are copied byte for
//!   byte for each vertex the result uses, in ascending input order ([`tinydecimate::remap`]'s
//!   numbering); unused vertices are dropped. The library only moves triangles (subset
//!   placement), so every kept vertex's attributes are bit-identical to an input vertex's.
//!   Nodes, transforms, scenes, materials, textures, samplers, images, skins, animations,
//!   cameras, `extras` and `extensions` are passed through untouched.
//! * **Writing.** One binary buffer: the bytes of every buffer view something still refers to
//!   (images, skins, animations, primitives not simplified) followed by the new primitives'
//!   indices (`u16` when the primitive has at most 65 535 vertices, else `u32`) and
//!   attributes, each in its own tightly packed view (rows padded to 4 bytes). Accessors and
//!   views only the old primitives used are dropped and the rest renumbered, unless the file
//!   uses an extension outside a list known not to refer to accessors or views; then every
//!   old accessor and view is kept. POSITION's `min`/`max` are recomputed; the other new
//!   accessors carry none (optional in glTF). `.glb` gets the buffer as its BIN chunk; `.gltf`
//!   gets it as a `.bin` file beside it (the output's name with `.bin`).
//!
//! Refused with a clear error: a primitive's accessor that is sparse, has no buffer view, or
//! is a matrix; a POSITION that is not `f32` VEC3 or not finite; attributes of different counts; an index
//! past the vertex count; an index count not a multiple of 3; files requiring Draco or
//! meshopt compression.

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::{json, Value};

/// Accessor `componentType` values.
const BYTE: u32 = 5120;
const UNSIGNED_BYTE: u32 = 5121;
const SHORT: u32 = 5122;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
/// `FLOAT` (public: `--integer` writes grid positions only into a float `POSITION`).
pub const FLOAT: u32 = 5126;

/// Extensions that refer to no accessor and no buffer view: with only these, accessors and
/// views the old primitives alone used are dropped.
const KNOWN_EXTENSIONS: &[&str] = &[
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_unlit",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_iridescence",
    "KHR_materials_anisotropy",
    "KHR_materials_dispersion",
    "KHR_materials_variants",
    "KHR_texture_transform",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
    "KHR_lights_punctual",
    "KHR_mesh_quantization",
];

/// One vertex attribute (or morph target attribute) of a primitive, packed: `count` elements
/// of `elem` bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct Stream {
    /// The attribute's name (`POSITION`, `TEXCOORD_0`, ...).
    pub semantic: String,
    /// The accessor's `componentType`.
    pub component_type: u32,
    /// The accessor's `type` (`SCALAR`, `VEC2`, `VEC3`, `VEC4`).
    pub ty: &'static str,
    /// The accessor's `normalized`.
    pub normalized: bool,
    /// Bytes per element.
    pub elem: usize,
    /// `count · elem` bytes.
    pub data: Vec<u8>,
}

impl Stream {
    /// Elements in the stream.
    pub fn count(&self) -> usize {
        self.data.len().checked_div(self.elem).unwrap_or(0)
    }

    /// Element `i`'s bytes.
    pub fn element(&self, i: usize) -> &[u8] {
        &self.data[i * self.elem..(i + 1) * self.elem]
    }
}

/// One triangle primitive.
#[derive(Clone, Debug, PartialEq)]
pub struct Primitive {
    /// Index of its mesh in `meshes`.
    pub mesh: usize,
    /// Index in the mesh's `primitives`.
    pub index: usize,
    /// POSITION as floats.
    pub positions: Vec<[f32; 3]>,
    /// Triangles (from the indices, or 0, 1, 2, ... when not indexed).
    pub triangles: Vec<[u32; 3]>,
    /// Every attribute, POSITION included, in the file's order.
    pub attributes: Vec<Stream>,
    /// Morph targets, each a set of per-vertex attributes.
    pub targets: Vec<Vec<Stream>>,
}

/// A glTF file as read: the JSON document, its buffers and its triangle primitives.
#[derive(Clone, Debug)]
pub struct GltfFile {
    /// The JSON document, as in the file.
    pub json: Value,
    /// Every buffer's bytes (at least its `byteLength`).
    pub buffers: Vec<Vec<u8>>,
    /// The triangle primitives, in mesh order.
    pub primitives: Vec<Primitive>,
    /// Primitives of other modes, passed through: "mesh 0 primitive 1 (mode 1)".
    pub passed_through: Vec<String>,
}

type R<T> = std::result::Result<T, String>;

/// Whether a path names a glTF file (`.gltf` or `.glb`, any case).
pub fn is_gltf_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// Reads a `.gltf` or `.glb` file; external buffers are looked up beside it.
pub fn load(path: &Path) -> anyhow::Result<GltfFile> {
    let bytes =
        std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
    let dir = path.parent().map(Path::to_path_buf);
    parse(&bytes, dir.as_deref()).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Splits a GLB into its JSON and BIN chunks, every length checked against the bytes there.
fn split_glb(bytes: &[u8]) -> R<(&[u8], Option<&[u8]>)> {
    let word = |at: usize| -> R<u32> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| {
                format!(
                    "GLB truncated at byte {at} (file has {} bytes)",
                    bytes.len()
                )
            })
    };
    let version = word(4)?;
    if version != 2 {
        return Err(format!("GLB version {version}, only 2 is read"));
    }
    let total = word(8)? as usize;
    if total > bytes.len() || total < 20 {
        return Err(format!(
            "GLB header says {total} bytes, the file has {}",
            bytes.len()
        ));
    }
    let bytes = &bytes[..total];
    let chunk = |at: usize| -> R<(u32, &[u8], usize)> {
        let len = word(at)? as usize;
        let ty = word(at + 4)?;
        let start = at + 8;
        let end = start
            .checked_add(len)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| {
                format!(
                    "GLB chunk at byte {at} claims {len} bytes, only {} remain (truncated?)",
                    bytes.len().saturating_sub(start)
                )
            })?;
        Ok((ty, &bytes[start..end], end))
    };
    let (ty, json, end) = chunk(12)?;
    // Chunks start on 4-byte boundaries; some writers leave the JSON chunk unpadded and put
    // the BIN chunk right after it (the validator's GLB_CHUNK_LENGTH_UNALIGNED): accept that.
    let is_bin = |at: usize| word(at + 4).is_ok_and(|t| t == 0x004E_4942);
    let next = if !is_bin(end.next_multiple_of(4)) && is_bin(end) {
        end
    } else {
        end.next_multiple_of(4)
    };
    if ty != 0x4E4F_534A {
        return Err("GLB's first chunk is not JSON".into());
    }
    let bin = if next + 8 <= bytes.len() {
        let (ty, bin, _) = chunk(next)?;
        if ty != 0x004E_4942 {
            return Err("GLB's second chunk is not BIN".into());
        }
        Some(bin)
    } else {
        None
    };
    Ok((json, bin))
}

/// Parses glTF bytes (GLB when they start with `glTF`, else JSON). `dir` is where external
/// buffers are looked up; `None` refuses them (the fuzz target and tests).
pub fn parse(bytes: &[u8], dir: Option<&Path>) -> R<GltfFile> {
    let (json_bytes, blob) = if bytes.starts_with(b"glTF") {
        split_glb(bytes)?
    } else {
        (bytes, None)
    };
    let mut json: Value =
        serde_json::from_slice(json_bytes).map_err(|e| format!("not JSON: {e}"))?;
    check_references(&mut json)?;
    let doc = gltf::Gltf::from_slice(json_bytes)
        .map_err(|e| format!("not a valid glTF 2.0 document: {e}"))?
        .document;
    for ext in doc.extensions_required() {
        if ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression" {
            return Err(format!(
                "requires {ext}: compressed geometry is not read (decompress it first, e.g. \
                 with gltf-transform)"
            ));
        }
    }
    let mut buffers = Vec::new();
    for b in doc.buffers() {
        let data: Vec<u8> = match b.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    format!(
                        "buffer {} is the GLB BIN chunk, which is missing",
                        b.index()
                    )
                })?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, payload) = rest
                        .split_once(";base64,")
                        .ok_or_else(|| format!("buffer {}: data URI is not base64", b.index()))?;
                    use base64::Engine as _;
                    base64::engine::general_purpose::STANDARD
                        .decode(payload)
                        .map_err(|e| format!("buffer {}: bad base64: {e}", b.index()))?
                } else {
                    let dir = dir.ok_or_else(|| {
                        format!(
                            "buffer {}: external file {uri:?} not available here",
                            b.index()
                        )
                    })?;
                    let name = percent_decode(uri);
                    std::fs::read(dir.join(&name))
                        .map_err(|e| format!("buffer {}: cannot read {name:?}: {e}", b.index()))?
                }
            }
        };
        if data.len() < b.length() {
            return Err(format!(
                "buffer {} has {} bytes, its byteLength says {}",
                b.index(),
                data.len(),
                b.length()
            ));
        }
        buffers.push(data);
    }
    let mut primitives = Vec::new();
    let mut passed_through = Vec::new();
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let (m, p) = (mesh.index(), prim.index());
            let here = |e: String| format!("mesh {m} primitive {p}: {e}");
            if prim.mode() != gltf::mesh::Mode::Triangles {
                passed_through.push(format!(
                    "mesh {m} primitive {p} (mode {})",
                    prim.mode().as_gl_enum()
                ));
                continue;
            }
            let pj = &json["meshes"][m]["primitives"][p];
            let attributes = read_attribute_set(&doc, &buffers, &pj["attributes"]).map_err(here)?;
            let pos = attributes
                .iter()
                .find(|s| s.semantic == "POSITION")
                .ok_or_else(|| here("no POSITION attribute".into()))?;
            if pos.component_type != FLOAT || pos.ty != "VEC3" {
                return Err(here(format!(
                    "POSITION is {} of component type {}, only float VEC3 is read",
                    pos.ty, pos.component_type
                )));
            }
            let n = pos.count();
            let positions: Vec<[f32; 3]> = pos
                .data
                .chunks_exact(12)
                .map(|c| {
                    let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
                    [f(0), f(4), f(8)]
                })
                .collect();
            if let Some(v) = positions
                .iter()
                .position(|p| p.iter().any(|c| !c.is_finite()))
            {
                return Err(here(format!("vertex {v} has a non-finite coordinate")));
            }
            let mut targets = Vec::new();
            if let Some(ts) = pj["targets"].as_array() {
                for t in ts {
                    targets.push(read_attribute_set(&doc, &buffers, t).map_err(here)?);
                }
            }
            for s in attributes.iter().chain(targets.iter().flatten()) {
                if s.count() != n {
                    return Err(here(format!(
                        "{} has {} elements, POSITION {n}",
                        s.semantic,
                        s.count()
                    )));
                }
            }
            let corners: Vec<u32> = match prim.indices() {
                Some(acc) => {
                    let s = read_accessor(&doc, &buffers, acc.index(), "indices")?;
                    let idx: Vec<u32> = match (s.component_type, s.ty) {
                        (UNSIGNED_BYTE, "SCALAR") => s.data.iter().map(|&b| u32::from(b)).collect(),
                        (UNSIGNED_SHORT, "SCALAR") => s
                            .data
                            .chunks_exact(2)
                            .map(|c| u32::from(u16::from_le_bytes([c[0], c[1]])))
                            .collect(),
                        (UNSIGNED_INT, "SCALAR") => s
                            .data
                            .chunks_exact(4)
                            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                            .collect(),
                        _ => return Err(here("indices are not unsigned integer scalars".into())),
                    };
                    if let Some(i) = idx.iter().position(|&i| i as usize >= n) {
                        return Err(here(format!(
                            "index {i} is {}, past the {n} vertices",
                            idx[i]
                        )));
                    }
                    idx
                }
                None => (0..n as u32).collect(),
            };
            if !corners.len().is_multiple_of(3) {
                return Err(here(format!(
                    "{} corners, not a multiple of 3",
                    corners.len()
                )));
            }
            let triangles = corners
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect();
            primitives.push(Primitive {
                mesh: m,
                index: p,
                positions,
                triangles,
                attributes,
                targets,
            });
        }
    }
    if primitives.is_empty() {
        return Err("no triangle primitive in the file".into());
    }
    Ok(GltfFile {
        json,
        buffers,
        primitives,
        passed_through,
    })
}

/// Every accessor, buffer view and buffer reference is in range. Checked before the `gltf`
/// crate validates the document: its validation (1.4.1) indexes the POSITION accessor
/// before checking the index, and panics on one past the end.
fn check_references(json: &mut Value) -> R<()> {
    let len = |j: &Value, k: &str| j[k].as_array().map_or(0, Vec::len);
    let check = |json: &mut Value, what: &str, n: usize, visit: Visitor| -> R<()> {
        let mut bad = None;
        visit(json, &mut |v| {
            if bad.is_none() && v.as_u64().is_none_or(|i| i >= n as u64) {
                bad = Some(v.to_string());
            }
        });
        match bad {
            Some(b) => Err(format!("a reference to {what} {b}, but there are {n}")),
            None => Ok(()),
        }
    };
    let accessors = len(json, "accessors");
    check(json, "accessor", accessors, visit_accessor_refs)?;
    let views = len(json, "bufferViews");
    check(json, "buffer view", views, visit_view_refs)?;
    let buffers = len(json, "buffers");
    check(json, "buffer", buffers, |j, f| {
        if let Some(vs) = j.get_mut("bufferViews").and_then(Value::as_array_mut) {
            for v in vs {
                if let Some(b) = v.get_mut("buffer") {
                    f(b);
                }
            }
        }
    })
}

/// `%20` and friends in a relative URI.
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A JSON object `{"NAME": accessor, ...}` read into streams, sorted by name.
fn read_attribute_set(doc: &gltf::Document, buffers: &[Vec<u8>], set: &Value) -> R<Vec<Stream>> {
    let map = set
        .as_object()
        .ok_or_else(|| "attributes are not an object".to_string())?;
    let mut out = Vec::new();
    for (name, idx) in map {
        let i = idx
            .as_u64()
            .ok_or_else(|| format!("{name}: accessor index is not a number"))?;
        out.push(read_accessor(doc, buffers, i as usize, name)?);
    }
    Ok(out)
}

/// Reads accessor `i` into a packed stream, every byte range checked first.
fn read_accessor(doc: &gltf::Document, buffers: &[Vec<u8>], i: usize, name: &str) -> R<Stream> {
    use gltf::accessor::{DataType, Dimensions};
    let acc = doc
        .accessors()
        .nth(i)
        .ok_or_else(|| format!("{name}: accessor {i} does not exist"))?;
    let here = |e: String| format!("{name} (accessor {i}): {e}");
    if acc.sparse().is_some() {
        return Err(here("sparse accessors are not read".into()));
    }
    let view = acc
        .view()
        .ok_or_else(|| here("no buffer view (all zeros) is not read".into()))?;
    let (component_type, csize) = match acc.data_type() {
        DataType::I8 => (BYTE, 1),
        DataType::U8 => (UNSIGNED_BYTE, 1),
        DataType::I16 => (SHORT, 2),
        DataType::U16 => (UNSIGNED_SHORT, 2),
        DataType::U32 => (UNSIGNED_INT, 4),
        DataType::F32 => (FLOAT, 4),
    };
    let (ty, n) = match acc.dimensions() {
        Dimensions::Scalar => ("SCALAR", 1),
        Dimensions::Vec2 => ("VEC2", 2),
        Dimensions::Vec3 => ("VEC3", 3),
        Dimensions::Vec4 => ("VEC4", 4),
        _ => return Err(here("matrix accessors are not read".into())),
    };
    let elem = csize * n;
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        return Err(here(format!(
            "byteStride {stride} below the element's {elem} bytes"
        )));
    }
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| here("missing buffer".into()))?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&e| e <= buffer.len())
        .ok_or_else(|| {
            here(format!(
                "buffer view {} ({} bytes at {}) runs past its buffer's {} bytes",
                view.index(),
                view.length(),
                view.offset(),
                buffer.len()
            ))
        })?;
    let bytes = &buffer[view.offset()..view_end];
    let count = acc.count();
    if count == 0 {
        return Err(here("count 0 (glTF asks for at least 1)".into()));
    }
    // The last element's end, checked before anything the size of `count` is allocated.
    let need = count
        .checked_sub(1)
        .map(|c| {
            c.checked_mul(stride)
                .and_then(|x| x.checked_add(acc.offset()))
                .and_then(|x| x.checked_add(elem))
        })
        .unwrap_or(Some(0));
    match need {
        Some(need) if need <= bytes.len() => {}
        _ => {
            return Err(here(format!(
                "{count} elements of {elem} bytes (stride {stride}, offset {}) do not fit its \
                 buffer view's {} bytes",
                acc.offset(),
                bytes.len()
            )))
        }
    }
    let mut data = Vec::with_capacity(count * elem);
    for k in 0..count {
        let at = acc.offset() + k * stride;
        data.extend_from_slice(&bytes[at..at + elem]);
    }
    Ok(Stream {
        semantic: name.to_string(),
        component_type,
        ty,
        normalized: acc.normalized(),
        elem,
        data,
    })
}

/// A simplified primitive: its triangles in the input's vertex numbering.
pub type Triangles = Vec<[u32; 3]>;

/// The kept vertices of `triangles` (over `n` vertices) packed in ascending order: the
/// renumbered triangles and the old index of each new vertex. Uses the library's
/// [`tinydecimate::remap::compact_vertices`].
pub fn compact(triangles: &[[u32; 3]], n: usize) -> R<(Vec<[u32; 3]>, Vec<usize>)> {
    let mut tris = triangles.to_vec();
    let mut remap = vec![0u32; n];
    let kept = tinydecimate::remap::compact_vertices(&mut tris, &mut remap)
        .map_err(|e| format!("compaction: {e}"))?;
    let mut old = Vec::with_capacity(kept);
    old.extend(
        remap
            .iter()
            .enumerate()
            .filter(|(_, &r)| r != u32::MAX)
            .map(|(i, _)| i),
    );
    Ok((tris, old))
}

/// Walks one kind of reference in the document, handing each to the closure.
type Visitor = fn(&mut Value, &mut dyn FnMut(&mut Value));

/// Accessor references in the document, visited mutably.
fn visit_accessor_refs(json: &mut Value, f: &mut dyn FnMut(&mut Value)) {
    if let Some(meshes) = json.get_mut("meshes").and_then(Value::as_array_mut) {
        for m in meshes {
            if let Some(prims) = m.get_mut("primitives").and_then(Value::as_array_mut) {
                for p in prims {
                    if let Some(a) = p.get_mut("attributes").and_then(Value::as_object_mut) {
                        a.values_mut().for_each(&mut *f);
                    }
                    if let Some(i) = p.get_mut("indices") {
                        f(i);
                    }
                    if let Some(ts) = p.get_mut("targets").and_then(Value::as_array_mut) {
                        for t in ts {
                            if let Some(t) = t.as_object_mut() {
                                t.values_mut().for_each(&mut *f);
                            }
                        }
                    }
                }
            }
        }
    }
    if let Some(skins) = json.get_mut("skins").and_then(Value::as_array_mut) {
        for s in skins {
            if let Some(i) = s.get_mut("inverseBindMatrices") {
                f(i);
            }
        }
    }
    if let Some(anims) = json.get_mut("animations").and_then(Value::as_array_mut) {
        for a in anims {
            if let Some(ss) = a.get_mut("samplers").and_then(Value::as_array_mut) {
                for s in ss {
                    for k in ["input", "output"] {
                        if let Some(i) = s.get_mut(k) {
                            f(i);
                        }
                    }
                }
            }
        }
    }
}

/// Buffer-view references in the document, visited mutably.
fn visit_view_refs(json: &mut Value, f: &mut dyn FnMut(&mut Value)) {
    if let Some(accs) = json.get_mut("accessors").and_then(Value::as_array_mut) {
        for a in accs {
            if let Some(v) = a.get_mut("bufferView") {
                f(v);
            }
            if let Some(sp) = a.get_mut("sparse") {
                for k in ["indices", "values"] {
                    if let Some(v) = sp.get_mut(k).and_then(|x| x.get_mut("bufferView")) {
                        f(v);
                    }
                }
            }
        }
    }
    if let Some(imgs) = json.get_mut("images").and_then(Value::as_array_mut) {
        for i in imgs {
            if let Some(v) = i.get_mut("bufferView") {
                f(v);
            }
        }
    }
}

/// Marks which of `count` indices `visit` reaches and renumbers them densely; unreached ones
/// map to `None`. `keep_all` keeps every index (identity map).
fn renumber(count: usize, json: &mut Value, keep_all: bool, visit: Visitor) -> Vec<Option<usize>> {
    let mut used = vec![keep_all; count];
    visit(json, &mut |v| {
        if let Some(i) = v.as_u64() {
            if let Some(u) = used.get_mut(i as usize) {
                *u = true;
            }
        }
    });
    let mut next = 0;
    let map: Vec<Option<usize>> = used
        .iter()
        .map(|&u| {
            u.then(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    visit(json, &mut |v| {
        if let Some(Some(n)) = v.as_u64().and_then(|i| map.get(i as usize)) {
            *v = json!(n);
        }
    });
    map
}

fn pad_to(bin: &mut Vec<u8>, align: usize, phase: usize) {
    while bin.len() % align != phase % align {
        bin.push(0);
    }
}

/// Writes the document with each triangle primitive replaced by its simplified triangles
/// (`results[k]` for `file.primitives[k]`, in the input's vertex numbering). Returns the
/// document (GLB bytes when `glb`, else JSON text whose buffer is the file `bin_name`) and,
/// for `.gltf`, the binary buffer.
pub fn write(
    file: &GltfFile,
    results: &[Triangles],
    glb: bool,
    bin_name: &str,
) -> R<(Vec<u8>, Option<Vec<u8>>)> {
    if results.len() != file.primitives.len() {
        return Err("one result per primitive".into());
    }
    let mut json = file.json.clone();
    let old_accessors = json["accessors"].as_array().map_or(0, Vec::len);
    let old_views = json["bufferViews"].as_array().map_or(0, Vec::len);
    let keep_all = json["extensionsUsed"].as_array().is_some_and(|a| {
        a.iter()
            .any(|e| !e.as_str().is_some_and(|e| KNOWN_EXTENSIONS.contains(&e)))
    });

    // New accessors and their data, numbered after the old ones for now.
    let mut new_accessors: Vec<Value> = Vec::new();
    let mut new_data: Vec<(Vec<u8>, usize, bool)> = Vec::new(); // (bytes, row, is indices)
    for (prim, tris) in file.primitives.iter().zip(results) {
        if tris.is_empty() {
            return Err(format!(
                "{} has no triangle left: glTF has no empty accessors",
                label(prim)
            ));
        }
        let (tris, old) = compact(tris, prim.positions.len())?;
        let pj = &mut json["meshes"][prim.mesh]["primitives"][prim.index];
        // Indices.
        let wide = old.len() > 65_535;
        let mut ib = Vec::with_capacity(tris.len() * 3 * if wide { 4 } else { 2 });
        for &v in tris.iter().flatten() {
            if wide {
                ib.extend_from_slice(&v.to_le_bytes());
            } else {
                ib.extend_from_slice(&(v as u16).to_le_bytes());
            }
        }
        pj["indices"] = json!(old_accessors + new_accessors.len());
        new_accessors.push(json!({
            "componentType": if wide { UNSIGNED_INT } else { UNSIGNED_SHORT },
            "count": tris.len() * 3,
            "type": "SCALAR",
        }));
        new_data.push((ib, 0, true));
        let mut add = |s: &Stream, slot: &mut Value, new_accessors: &mut Vec<Value>| {
            let mut d = Vec::with_capacity(old.len() * s.elem);
            for &o in &old {
                d.extend_from_slice(s.element(o));
            }
            let mut a = json!({
                "componentType": s.component_type,
                "count": old.len(),
                "type": s.ty,
            });
            if s.normalized {
                a["normalized"] = json!(true);
            }
            if s.semantic == "POSITION" && s.component_type == FLOAT {
                let mut lo = [f32::INFINITY; 3];
                let mut hi = [f32::NEG_INFINITY; 3];
                for c in d.chunks_exact(12) {
                    for k in 0..3 {
                        let x = f32::from_le_bytes([
                            c[4 * k],
                            c[4 * k + 1],
                            c[4 * k + 2],
                            c[4 * k + 3],
                        ]);
                        lo[k] = lo[k].min(x);
                        hi[k] = hi[k].max(x);
                    }
                }
                if !old.is_empty() {
                    a["min"] = json!(lo);
                    a["max"] = json!(hi);
                }
            }
            *slot = json!(old_accessors + new_accessors.len());
            new_accessors.push(a);
            new_data.push((d, s.elem, false));
        };
        for s in &prim.attributes {
            add(s, &mut pj["attributes"][&s.semantic], &mut new_accessors);
        }
        for (t, set) in prim.targets.iter().enumerate() {
            for s in set {
                add(s, &mut pj["targets"][t][&s.semantic], &mut new_accessors);
            }
        }
    }

    // Old accessors still referred to, renumbered; new ones after them.
    let total_acc = old_accessors + new_accessors.len();
    let acc_map = renumber(total_acc, &mut json, keep_all, visit_accessor_refs);
    let kept_acc: Vec<Value> = json["accessors"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .into_iter()
        .zip(&acc_map)
        .filter_map(|(a, m)| m.map(|_| a))
        .collect();
    let kept_old_acc = kept_acc.len();
    json["accessors"] = Value::Array(kept_acc);

    // Old views still referred to (by kept accessors, sparse parts, images), renumbered.
    let view_map = renumber(old_views, &mut json, keep_all, visit_view_refs);
    let mut bin = Vec::new();
    let mut views = Vec::new();
    for (k, v) in json["bufferViews"]
        .as_array()
        .cloned()
        .unwrap_or_default()
        .into_iter()
        .enumerate()
    {
        if view_map.get(k).copied().flatten().is_none() {
            continue;
        }
        let b = v["buffer"].as_u64().unwrap_or(u64::MAX) as usize;
        let off = v["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = v["byteLength"].as_u64().unwrap_or(0) as usize;
        let src = file
            .buffers
            .get(b)
            .and_then(|buf| buf.get(off..off.checked_add(len)?))
            .ok_or_else(|| format!("buffer view {k} runs past its buffer"))?;
        pad_to(&mut bin, 8, off);
        let mut v = v;
        v["buffer"] = json!(0);
        v["byteOffset"] = json!(bin.len());
        bin.extend_from_slice(src);
        views.push(v);
    }
    // The new accessors' views.
    let mut accessors = json["accessors"].as_array().cloned().unwrap_or_default();
    for (a, (d, row, is_index)) in new_accessors.into_iter().zip(new_data) {
        pad_to(&mut bin, 4, 0);
        let mut a = a;
        a["bufferView"] = json!(views.len());
        let mut v = json!({"buffer": 0, "byteOffset": bin.len(), "target": if is_index { 34963 } else { 34962 }});
        if !is_index && row % 4 != 0 {
            // Vertex attribute rows start on 4-byte boundaries.
            let stride = row.next_multiple_of(4);
            for e in d.chunks_exact(row) {
                bin.extend_from_slice(e);
                bin.extend(std::iter::repeat_n(0, stride - row));
            }
            v["byteStride"] = json!(stride);
            v["byteLength"] = json!((d.len() / row) * stride);
        } else {
            bin.extend_from_slice(&d);
            v["byteLength"] = json!(d.len());
        }
        views.push(v);
        accessors.push(a);
    }
    debug_assert_eq!(accessors.len(), kept_old_acc + (total_acc - old_accessors));
    json["accessors"] = Value::Array(accessors);
    json["bufferViews"] = Value::Array(views);
    let mut buffer = json!({"byteLength": bin.len()});
    if !glb {
        buffer["uri"] = json!(bin_name);
    }
    json["buffers"] = json!([buffer]);
    let text = serde_json::to_vec(&json).map_err(|e| e.to_string())?;
    if !glb {
        return Ok((text, Some(bin)));
    }
    let mut text = text;
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let total32 = u32::try_from(total).map_err(|_| "output over 4 GB".to_string())?;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total32.to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    Ok((out, None))
}

/// Writes [`fn@write`]'s output to `path` (`.glb` or `.gltf`, the `.bin` beside it).
pub fn save(path: &Path, file: &GltfFile, results: &[Triangles]) -> anyhow::Result<()> {
    let glb = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let bin_path = path.with_extension("bin");
    let bin_name = bin_path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("buffer.bin")
        .to_string();
    let (doc, bin) = write(file, results, glb, &bin_name)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    std::fs::write(path, doc)
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
    if let Some(bin) = bin {
        std::fs::write(&bin_path, bin)
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", bin_path.display()))?;
    }
    Ok(())
}

/// Primitives by mesh, for reports: "mesh 0 primitive 1".
pub fn label(p: &Primitive) -> String {
    format!("mesh {} primitive {}", p.mesh, p.index)
}

/// How many of each attribute the primitives carry, for a one-line summary.
pub fn attribute_summary(file: &GltfFile) -> String {
    let mut m: BTreeMap<&str, usize> = BTreeMap::new();
    for p in &file.primitives {
        for s in &p.attributes {
            *m.entry(s.semantic.as_str()).or_default() += 1;
        }
    }
    m.keys().copied().collect::<Vec<_>>().join(", ")
}

// ---------------------------------------------------------------------------------------------
// The scene, and the geometry the plain loader sees

/// A transform, row-major, acting on column vectors.
pub type Transform = [[f64; 4]; 4];

const IDENTITY: Transform = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

fn mul(a: &Transform, b: &Transform) -> Transform {
    let mut m = [[0.0; 4]; 4];
    for (r, row) in m.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    m
}

fn numbers(v: Option<&Value>) -> Option<Vec<f64>> {
    v?.as_array()?.iter().map(Value::as_f64).collect()
}

/// A node's local transform: its `matrix` (column-major in the file), else translation ·
/// rotation · scale.
fn local(node: &Value) -> Transform {
    if let Some(m) = numbers(node.get("matrix")).filter(|m| m.len() == 16) {
        let mut out = [[0.0; 4]; 4];
        for c in 0..4 {
            for r in 0..4 {
                out[r][c] = m[c * 4 + r];
            }
        }
        return out;
    }
    let t = numbers(node.get("translation"))
        .filter(|v| v.len() == 3)
        .unwrap_or(vec![0.0; 3]);
    let [x, y, z, w] = numbers(node.get("rotation"))
        .filter(|v| v.len() == 4)
        .map_or([0.0, 0.0, 0.0, 1.0], |q| [q[0], q[1], q[2], q[3]]);
    let s = numbers(node.get("scale"))
        .filter(|v| v.len() == 3)
        .unwrap_or(vec![1.0; 3]);
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let mut m = IDENTITY;
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = r[i][j] * s[j];
        }
        m[i][3] = t[i];
    }
    m
}

/// One mesh placed in the scene by a node.
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    /// The node.
    pub node: usize,
    /// The mesh it draws.
    pub mesh: usize,
    /// The node's world transform (composed down the node tree).
    pub world: Transform,
}

/// Where the scene draws meshes, as a viewer does: every node of the default scene (or of the
/// first, or every root node when there is no scene), depth first down the node tree, each
/// with its world transform. A mesh several nodes name is drawn once per node (instancing);
/// a node reached twice (a cycle, invalid glTF) is entered once.
pub fn placements(json: &Value) -> Vec<Placement> {
    let nodes = json.get("nodes").and_then(Value::as_array);
    let n = nodes.map_or(0, Vec::len);
    let scenes = json.get("scenes").and_then(Value::as_array);
    let pick = json.get("scene").and_then(Value::as_u64).unwrap_or(0) as usize;
    let roots: Vec<usize> = match scenes
        .and_then(|s| s.get(pick))
        .and_then(|s| s.get("nodes"))
    {
        Some(list) => numbers(Some(list))
            .unwrap_or_default()
            .into_iter()
            .map(|n| n as usize)
            .collect(),
        None => {
            // No scene: every node that is no other node's child.
            let mut child = vec![false; n];
            for node in nodes.into_iter().flatten() {
                for c in numbers(node.get("children")).unwrap_or_default() {
                    if let Some(x) = child.get_mut(c as usize) {
                        *x = true;
                    }
                }
            }
            (0..n).filter(|&i| !child[i]).collect()
        }
    };
    let mut out = Vec::new();
    let mut seen = vec![false; n];
    let mut stack: Vec<(usize, Transform)> =
        roots.into_iter().rev().map(|r| (r, IDENTITY)).collect();
    while let Some((k, parent)) = stack.pop() {
        let (Some(node), Some(s)) = (nodes.and_then(|l| l.get(k)), seen.get_mut(k)) else {
            continue;
        };
        if std::mem::replace(s, true) {
            continue;
        }
        let world = mul(&parent, &local(node));
        if let Some(m) = node.get("mesh").and_then(Value::as_u64) {
            out.push(Placement {
                node: k,
                mesh: m as usize,
                world,
            });
        }
        for c in numbers(node.get("children"))
            .unwrap_or_default()
            .into_iter()
            .rev()
        {
            stack.push((c as usize, world));
        }
    }
    out
}

/// How the scene draws the triangle primitives, against how the file stores them (each
/// primitive once, as `simplify` reads and counts them).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Instancing {
    /// Triangles of the triangle primitives, each primitive once.
    pub stored: usize,
    /// Triangles the scene draws: each primitive once per node that places its mesh.
    pub drawn: usize,
    /// Meshes with triangles that the scene draws other than once: (mesh, times drawn).
    pub meshes: Vec<(usize, usize)>,
    /// Whether some node placing a mesh has a transform other than the identity.
    pub transformed: bool,
}

impl Instancing {
    /// Counts `file`'s triangles stored and drawn ([`placements`]).
    pub fn of(file: &GltfFile) -> Instancing {
        let places = placements(&file.json);
        let mut times: BTreeMap<usize, usize> = BTreeMap::new();
        for p in &file.primitives {
            times.entry(p.mesh).or_insert(0);
        }
        for p in &places {
            if let Some(t) = times.get_mut(&p.mesh) {
                *t += 1;
            }
        }
        let tris = |m: usize| -> usize {
            file.primitives
                .iter()
                .filter(|p| p.mesh == m)
                .map(|p| p.triangles.len())
                .sum()
        };
        Instancing {
            stored: file.primitives.iter().map(|p| p.triangles.len()).sum(),
            drawn: times.iter().map(|(&m, &t)| t * tris(m)).sum(),
            meshes: times.into_iter().filter(|&(_, t)| t != 1).collect(),
            transformed: places.iter().any(|pl| {
                pl.world != IDENTITY && file.primitives.iter().any(|p| p.mesh == pl.mesh)
            }),
        }
    }

    /// "mesh 1 drawn 2 times, mesh 3 not drawn" (empty when every mesh is drawn once).
    pub fn meshes_text(&self) -> String {
        self.meshes
            .iter()
            .map(|&(m, t)| match t {
                0 => format!("mesh {m} in no node (not drawn)"),
                t => format!("mesh {m} drawn {t} times"),
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// The geometry of `file` as one mesh, as `simplify` sees the file: every triangle primitive
/// once, in file order, in its mesh's own coordinates (node transforms are not applied, and a
/// mesh several nodes place is counted once), its vertices numbered after the previous
/// primitive's. With it, the notes: attributes not carried, primitives that are not
/// triangles, and, when the scene draws the meshes otherwise (moved, instanced or not at
/// all), how.
pub fn geometry(file: &GltfFile) -> (crate::io::MeshData, crate::io::LoadNotes) {
    let mut mesh = crate::io::MeshData::default();
    let mut attributes: BTreeMap<&str, usize> = BTreeMap::new();
    let mut targets = 0;
    for p in &file.primitives {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&p.positions);
        mesh.triangles
            .extend(p.triangles.iter().map(|t| t.map(|i| base + i)));
        for s in p.attributes.iter().filter(|s| s.semantic != "POSITION") {
            *attributes.entry(s.semantic.as_str()).or_default() += 1;
        }
        targets += p.targets.len();
    }
    let mut notes = crate::io::LoadNotes::default();
    let n = file.primitives.len();
    notes.dropped = attributes
        .iter()
        .map(|(a, k)| format!("{a} ({k} of {n} primitives)"))
        .collect();
    if targets > 0 {
        notes.dropped.push(format!("{targets} morph target(s)"));
    }
    for p in &file.passed_through {
        notes.other.push(format!("{p} is not triangles: not read"));
    }
    let inst = Instancing::of(file);
    if inst.transformed || !inst.meshes.is_empty() {
        let mut s = format!(
            "read as `simplify` reads glTF: each of the {n} triangle primitive(s) once, in its \
             mesh's own coordinates ({} triangles; node transforms not applied)",
            inst.stored
        );
        if !inst.meshes.is_empty() {
            s += &format!(
                "; the scene draws {} triangles: {}",
                inst.drawn,
                inst.meshes_text()
            );
        }
        notes.other.push(s);
    }
    (mesh, notes)
}

/// The element `i` of a TEXCOORD stream as floats (`FLOAT`, or normalized `UNSIGNED_BYTE` /
/// `UNSIGNED_SHORT`, the three component types glTF allows for it).
pub fn uv_of(s: &Stream, i: usize) -> Option<[f64; 2]> {
    let e = s.data.get(i * s.elem..(i + 1) * s.elem)?;
    Some(match s.component_type {
        5126 => [0, 1].map(|k| {
            f64::from(f32::from_le_bytes([
                e[4 * k],
                e[4 * k + 1],
                e[4 * k + 2],
                e[4 * k + 3],
            ]))
        }),
        5121 => [0, 1].map(|k| f64::from(e[k]) / 255.0),
        5123 => [0, 1].map(|k| f64::from(u16::from_le_bytes([e[2 * k], e[2 * k + 1]])) / 65535.0),
        _ => return None,
    })
}

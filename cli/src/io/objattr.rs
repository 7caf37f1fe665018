//! OBJ with texture coordinates and normals, carried through a simplification.
//!
//! A face corner `p/t/n` names a position, a texture coordinate and a normal separately; a
//! renderer holds one vertex per distinct triple, and so does this reader: two corners are the
//! same vertex only when all three indices match (so a UV seam splits a position into two
//! vertices, which the simplifier sees as an open boundary). Faces are grouped by their
//! `usemtl` material; each group is a mesh of its own, simplified on its own like a glTF
//! primitive (their shared border may open). The `v`, `vt` and `vn` lines the result uses are
//! written back as their original text (bit-identical values, vertex colours after `v x y z`
//! included), in file order; `mtllib` lines are kept; every group's triangles follow its
//! `usemtl`. Polygons are split by [`crate::io::triangulate`]. Lines other than `v`, `vt`,
//! `vn`, `f`, `usemtl` and `mtllib` (`o`, `g`, `s`, `l`, `p`, ...) are not carried.

use std::collections::HashMap;
use std::fmt::Write as _;

/// A corner: 0-based position, texture coordinate and normal (`None` when the corner has
/// none).
pub type Corner = (u32, Option<u32>, Option<u32>);

/// One material group: its vertices (distinct corners) and triangles over them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Group {
    /// The `usemtl` name (`None` before any `usemtl`).
    pub material: Option<String>,
    /// The distinct corners, numbered by first appearance.
    pub vertices: Vec<Corner>,
    /// Triangles over `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

/// An OBJ file with attributes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjFile {
    /// `mtllib` lines, verbatim.
    pub mtllib: Vec<String>,
    /// `v` positions, parsed.
    pub positions: Vec<[f32; 3]>,
    /// `v` lines' text after `v`.
    pub v_text: Vec<String>,
    /// `vt` lines' text after `vt`.
    pub vt_text: Vec<String>,
    /// `vn` lines' text after `vn`.
    pub vn_text: Vec<String>,
    /// Material groups in order of first use.
    pub groups: Vec<Group>,
}

impl ObjFile {
    /// Group `g` as a mesh: one position per vertex (corner).
    pub fn mesh(&self, g: usize) -> crate::io::MeshData {
        let gr = &self.groups[g];
        crate::io::MeshData {
            positions: gr
                .vertices
                .iter()
                .map(|c| self.positions[c.0 as usize])
                .collect(),
            triangles: gr.triangles.clone(),
        }
    }
}

/// Whether an OBJ's faces use texture coordinates or normals (a corner `a/b`, `a//c` or
/// `a/b/c`); `vt`/`vn` lines no face refers to do not count.
pub fn has_attributes(bytes: &[u8]) -> bool {
    bytes.split(|&b| b == b'\n').any(|l| {
        let l = l.trim_ascii_start();
        (l.starts_with(b"f ") || l.starts_with(b"f\t"))
            && l.split(|c| c.is_ascii_whitespace()).any(|corner| {
                corner
                    .iter()
                    .position(|&c| c == b'/')
                    .is_some_and(|k| corner[k + 1..].iter().any(u8::is_ascii_digit))
            })
    })
}

fn resolve(tok: &str, count: usize, what: &str, line: usize) -> Result<u32, String> {
    let i: i64 = tok
        .parse()
        .map_err(|_| format!("line {line}: {what} index {tok:?} is not an integer"))?;
    let n = count as i64;
    let r = if i > 0 { i - 1 } else { n + i };
    if i == 0 || r < 0 || r >= n {
        return Err(format!(
            "line {line}: {what} index {i} but there are {count} at this point"
        ));
    }
    Ok(r as u32)
}

/// Parses OBJ text, keeping texture coordinates, normals and materials.
pub fn parse(bytes: &[u8]) -> Result<ObjFile, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| format!("not UTF-8 text: {e}"))?;
    let mut f = ObjFile::default();
    let mut ids: Vec<HashMap<Corner, u32>> = Vec::new();
    let mut current: Option<usize> = None;
    let mut material: Option<String> = None;
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let l = raw.split('#').next().unwrap_or("").trim();
        let mut it = l.split_whitespace();
        let Some(key) = it.next() else { continue };
        let rest = l[key.len()..].trim().to_string();
        match key {
            "v" => {
                let c: Vec<f32> = it
                    .take(3)
                    .map(|t| t.parse::<f32>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| format!("line {line}: bad vertex {l:?}"))?;
                if c.len() < 3 || c.iter().any(|x| !x.is_finite()) {
                    return Err(format!("line {line}: bad vertex {l:?}"));
                }
                f.positions.push([c[0], c[1], c[2]]);
                f.v_text.push(rest);
            }
            "vt" => f.vt_text.push(rest),
            "vn" => f.vn_text.push(rest),
            "mtllib" => f.mtllib.push(l.to_string()),
            "usemtl" => {
                material = Some(rest);
                current = None;
            }
            "f" => {
                let g = match current {
                    Some(g) => g,
                    None => {
                        let g = f
                            .groups
                            .iter()
                            .position(|g| g.material == material)
                            .unwrap_or_else(|| {
                                f.groups.push(Group {
                                    material: material.clone(),
                                    ..Group::default()
                                });
                                ids.push(HashMap::new());
                                f.groups.len() - 1
                            });
                        current = Some(g);
                        g
                    }
                };
                let mut poly = Vec::new();
                for c in it {
                    let mut p = c.split('/');
                    let pi = resolve(p.next().unwrap_or(""), f.positions.len(), "vertex", line)?;
                    let ti = match p.next() {
                        None | Some("") => None,
                        Some(t) => Some(resolve(t, f.vt_text.len(), "texture coordinate", line)?),
                    };
                    let ni = match p.next() {
                        None | Some("") => None,
                        Some(t) => Some(resolve(t, f.vn_text.len(), "normal", line)?),
                    };
                    let key = (pi, ti, ni);
                    let gr = &mut f.groups[g];
                    let id = *ids[g].entry(key).or_insert_with(|| {
                        gr.vertices.push(key);
                        (gr.vertices.len() - 1) as u32
                    });
                    poly.push(id);
                }
                if poly.len() < 3 {
                    return Err(format!("line {line}: face with fewer than 3 corners"));
                }
                if poly.len() == 3 {
                    f.groups[g].triangles.push([poly[0], poly[1], poly[2]]);
                } else {
                    // Ear clipping on the polygon's own corners, then back to group vertices.
                    let gr = &f.groups[g];
                    let pos: Vec<[f32; 3]> = poly
                        .iter()
                        .map(|&v| f.positions[gr.vertices[v as usize].0 as usize])
                        .collect();
                    let local: Vec<u32> = (0..poly.len() as u32).collect();
                    let tris = crate::io::triangulate(&pos, &local);
                    f.groups[g]
                        .triangles
                        .extend(tris.iter().map(|t| t.map(|k| poly[k as usize])));
                }
            }
            _ => {}
        }
    }
    if f.groups.iter().all(|g| g.triangles.is_empty()) {
        return Err("no triangles in file".into());
    }
    Ok(f)
}

/// Writes the groups with `results[g]` (triangles over group `g`'s vertices): only the `v`,
/// `vt` and `vn` lines they use, in file order, as their original text.
pub fn write(f: &ObjFile, results: &[Vec<[u32; 3]>]) -> String {
    let mut used_v = vec![false; f.v_text.len()];
    let mut used_t = vec![false; f.vt_text.len()];
    let mut used_n = vec![false; f.vn_text.len()];
    for (g, tris) in f.groups.iter().zip(results) {
        for &v in tris.iter().flatten() {
            let (p, t, n) = g.vertices[v as usize];
            used_v[p as usize] = true;
            if let Some(t) = t {
                used_t[t as usize] = true;
            }
            if let Some(n) = n {
                used_n[n as usize] = true;
            }
        }
    }
    let number = |used: &[bool]| {
        let mut next = 0u32;
        used.iter()
            .map(|&u| {
                u.then(|| {
                    next += 1;
                    next
                })
            })
            .collect::<Vec<Option<u32>>>()
    };
    let (nv, nt, nn) = (number(&used_v), number(&used_t), number(&used_n));
    let mut out = String::new();
    for l in &f.mtllib {
        let _ = writeln!(out, "{l}");
    }
    for (k, s) in f.v_text.iter().enumerate() {
        if used_v[k] {
            let _ = writeln!(out, "v {s}");
        }
    }
    for (k, s) in f.vt_text.iter().enumerate() {
        if used_t[k] {
            let _ = writeln!(out, "vt {s}");
        }
    }
    for (k, s) in f.vn_text.iter().enumerate() {
        if used_n[k] {
            let _ = writeln!(out, "vn {s}");
        }
    }
    for (g, tris) in f.groups.iter().zip(results) {
        if let Some(m) = &g.material {
            let _ = writeln!(out, "usemtl {m}");
        }
        for t in tris {
            out.push('f');
            for &v in t {
                let (p, tt, n) = g.vertices[v as usize];
                let _ = write!(out, " {}", nv[p as usize].unwrap_or(0));
                match (tt, n) {
                    (None, None) => {}
                    (Some(t), None) => {
                        let _ = write!(out, "/{}", nt[t as usize].unwrap_or(0));
                    }
                    (None, Some(n)) => {
                        let _ = write!(out, "//{}", nn[n as usize].unwrap_or(0));
                    }
                    (Some(t), Some(n)) => {
                        let _ = write!(
                            out,
                            "/{}/{}",
                            nt[t as usize].unwrap_or(0),
                            nn[n as usize].unwrap_or(0)
                        );
                    }
                }
            }
            out.push('\n');
        }
    }
    out
}

/// The texture coordinates primitive `p` of `file` is drawn with: `TEXCOORD_n` of its
/// material's `baseColorTexture`, else `TEXCOORD_0`; `None` when the primitive has not that
/// attribute.
pub fn gltf_texcoord_name(
    file: &crate::io::gltf::GltfFile,
    p: &crate::io::gltf::Primitive,
) -> Option<String> {
    let material = &file.json["meshes"][p.mesh]["primitives"][p.index]["material"];
    let n = material
        .as_u64()
        .and_then(|m| {
            file.json["materials"][m as usize]["pbrMetallicRoughness"]["baseColorTexture"]
                ["texCoord"]
                .as_u64()
        })
        .unwrap_or(0);
    let name = format!("TEXCOORD_{n}");
    p.attributes
        .iter()
        .any(|s| s.semantic == name)
        .then_some(name)
}

/// Element `i` of a NORMAL stream as floats: `FLOAT`, or normalized `BYTE` / `SHORT`
/// (`KHR_mesh_quantization`).
fn gltf_normal(s: &crate::io::gltf::Stream, i: usize) -> Option<[f32; 3]> {
    let e = s.data.get(i * s.elem..(i + 1) * s.elem)?;
    let at = |k: usize, w: usize| e.get(k * w..(k + 1) * w);
    let mut out = [0.0f32; 3];
    for (k, o) in out.iter_mut().enumerate() {
        *o = match (s.component_type, s.normalized) {
            (5126, _) => {
                let b = at(k, 4)?;
                f32::from_le_bytes([b[0], b[1], b[2], b[3]])
            }
            (5120, true) => (f32::from(at(k, 1)?[0] as i8) / 127.0).max(-1.0),
            (5122, true) => {
                let b = at(k, 2)?;
                (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
            }
            _ => return None,
        };
    }
    Some(out)
}

/// A glTF file's triangle primitives as an OBJ with attributes, to write with [`fn@write`]: one
/// `v` per glTF vertex, all primitives' vertices in file order (so the OBJ's numbering is
/// [`crate::io::gltf::geometry`]'s); one `vt` per vertex of a primitive with the texture
/// coordinates its material reads ([`gltf_texcoord_name`]), written `u 1-v` because glTF's v
/// runs down the image and OBJ's up; one `vn` per vertex of a primitive with NORMAL; each
/// primitive its own group, `usemtl` its material's name (blanks made `_`; `material_N` when
/// it has none, `default` without a material). Also returns what OBJ cannot hold and is not written (other
/// attributes, morph targets, the materials themselves, node transforms), for one line of
/// output.
pub fn from_gltf(file: &crate::io::gltf::GltfFile) -> (ObjFile, Vec<String>) {
    let mut f = ObjFile::default();
    let mut skipped: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    let mut targets = false;
    for p in &file.primitives {
        let uv_name = gltf_texcoord_name(file, p);
        let uv = uv_name
            .as_ref()
            .and_then(|n| p.attributes.iter().find(|s| &s.semantic == n));
        let normal = p.attributes.iter().find(|s| s.semantic == "NORMAL");
        let mut normals: Option<Vec<[f32; 3]>> =
            normal.and_then(|s| (0..p.positions.len()).map(|i| gltf_normal(s, i)).collect());
        if normal.is_some() && normals.is_none() {
            skipped.insert("NORMAL (not float or normalized)".into());
            normals = None;
        }
        for s in &p.attributes {
            let written = s.semantic == "POSITION"
                || (s.semantic == "NORMAL" && normals.is_some())
                || Some(&s.semantic) == uv_name.as_ref();
            if !written {
                skipped.insert(s.semantic.clone());
            }
        }
        targets |= !p.targets.is_empty();
        let v0 = f.positions.len() as u32;
        let t0 = f.vt_text.len() as u32;
        let n0 = f.vn_text.len() as u32;
        for q in &p.positions {
            f.positions.push(*q);
            f.v_text.push(format!("{} {} {}", q[0], q[1], q[2]));
        }
        if let Some(s) = uv {
            for i in 0..p.positions.len() {
                let [u, v] = crate::io::gltf::uv_of(s, i).unwrap_or([0.0; 2]);
                f.vt_text.push(format!("{} {}", u as f32, (1.0 - v) as f32));
            }
        }
        if let Some(ns) = &normals {
            for n in ns {
                f.vn_text.push(format!("{} {} {}", n[0], n[1], n[2]));
            }
        }
        let material = file.json["meshes"][p.mesh]["primitives"][p.index]["material"]
            .as_u64()
            .map_or("default".to_string(), |m| {
                file.json["materials"][m as usize]["name"]
                    .as_str()
                    .map(|n| n.split_whitespace().collect::<Vec<_>>().join("_"))
                    .filter(|n| !n.is_empty())
                    .unwrap_or(format!("material_{m}"))
            });
        let n = p.positions.len() as u32;
        f.groups.push(Group {
            material: Some(material),
            vertices: (0..n)
                .map(|i| (v0 + i, uv.map(|_| t0 + i), normals.as_ref().map(|_| n0 + i)))
                .collect(),
            triangles: p.triangles.clone(),
        });
    }
    let mut not_written: Vec<String> = skipped.into_iter().collect();
    if targets {
        not_written.push("morph targets".into());
    }
    if file.json["materials"]
        .as_array()
        .is_some_and(|m| !m.is_empty())
    {
        not_written.push("materials (no .mtl; `usemtl` names only)".into());
    }
    let inst = crate::io::gltf::Instancing::of(file);
    if inst.transformed || !inst.meshes.is_empty() {
        not_written.push("the scene's nodes (each primitive once, untransformed)".into());
    }
    (f, not_written)
}

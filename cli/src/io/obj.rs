//! OBJ in (`v` and `f` lines, the file's numbering kept) and out (see [`crate::io`]).

use std::fmt::Write as _;

use super::{triangulate, used_vertices, LoadNotes, MeshData, Parsed};

pub(crate) fn parse_obj(bytes: &[u8]) -> Parsed {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let at = e.valid_up_to();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        format!("line {line} (byte offset {at}): not valid UTF-8 text")
    })?;
    let mut mesh = MeshData::default();
    let mut notes = LoadNotes::default();
    // Polygons with more than 3 corners: (index of the triangle slot they go to, corners),
    // split once every vertex is read (a face may refer to a vertex defined later).
    let mut polygons: Vec<(usize, Vec<u32>)> = Vec::new();
    let (mut vt, mut vn, mut other) = (0usize, 0usize, std::collections::BTreeSet::new());
    // Largest vertex index referenced by a face and the line it is on, checked at the end
    // (an OBJ face may refer to a vertex defined later).
    let mut max_ref: Option<(usize, usize)> = None;
    // Vertices with a NaN or infinite coordinate (vertex, line, token): refused only if a
    // face uses one, as the library only reads the vertices its triangles use.
    let mut non_finite: Vec<(usize, usize, String)> = Vec::new();
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
                    if !c.is_finite() && non_finite.len() < MAX_NON_FINITE_NOTED {
                        non_finite.push((mesh.positions.len(), line_no, tok.to_string()));
                    }
                }
                mesh.positions.push(p);
            }
            "vt" => vt += 1,
            "vn" => vn += 1,
            "vp" | "l" | "p" | "curv" | "curv2" | "surf" | "usemtl" | "mtllib" => {
                other.insert(keyword.to_string());
            }
            "f" => {
                let corners: Vec<&str> = tokens.collect();
                if corners.len() < 3 {
                    return Err(format!(
                        "line {line_no}: face with {} corner(s); a face needs at least 3",
                        corners.len()
                    ));
                }
                let mut face = vec![0u32; corners.len()];
                for (slot, tok) in face.iter_mut().zip(&corners) {
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
                if let [a, b, c] = face[..] {
                    mesh.triangles.push([a, b, c]);
                } else {
                    polygons.push((mesh.triangles.len(), face));
                }
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
    if !non_finite.is_empty() {
        let used = used_vertices(&mesh.positions, &mesh.triangles, &polygons);
        if let Some((_, line_no, tok)) = non_finite.iter().find(|(v, _, _)| used[*v]) {
            return Err(format!(
                "line {line_no}: non-finite vertex coordinate {tok:?} (the vertex is used by a face)"
            ));
        }
    }
    if !polygons.is_empty() {
        // Splice each polygon's triangles in at its place in the file.
        let tris = std::mem::take(&mut mesh.triangles);
        let mut out = Vec::with_capacity(tris.len() + polygons.len() * 2);
        let mut next = 0;
        for (at, face) in &polygons {
            out.extend_from_slice(&tris[next..*at]);
            next = *at;
            let split = triangulate(&mesh.positions, face);
            notes.polygons_split += 1;
            notes.triangles_from_polygons += split.len();
            out.extend(split);
        }
        out.extend_from_slice(&tris[next..]);
        mesh.triangles = out;
    }
    if vt > 0 {
        notes.dropped.push(format!("{vt} texture coordinates (vt)"));
    }
    if vn > 0 {
        notes.dropped.push(format!("{vn} normals (vn)"));
    }
    if !other.is_empty() {
        let o: Vec<String> = other.into_iter().collect();
        notes.dropped.push(format!("`{}` lines", o.join("`, `")));
    }
    Ok((mesh, notes))
}

/// Non-finite vertices of an OBJ file noted with their line; past this many, the first used
/// one is still found by [`validate`] (without its line).
pub(crate) const MAX_NON_FINITE_NOTED: usize = 1024;

pub(crate) fn obj_bytes(mesh: &MeshData) -> Vec<u8> {
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

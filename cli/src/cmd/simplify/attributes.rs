//! `--attribute-weights`: the vertex attributes a textured part hands the attribute-aware
//! stored quadric (`tinydecimate::cost::AttributeQuadric`), its texture coordinates (those
//! the UV stretch figure reads) and its normals (glTF `NORMAL`, OBJ `vn`).

use anyhow::{bail, Result};

use super::{Args, PlacementArg, QuadricArg};
use crate::simplify::{Attributes, ATTRIBUTES};

/// The attributes for one part of `vertices` vertices, when `--attribute-weights` asks for
/// them: `[u, v, nx, ny, nz]` per vertex, zeros and a zero weight for what the part lacks (a
/// note says so). Refused without `--quadric stored --placement subset`.
pub(super) fn for_part(
    args: &Args,
    label: &str,
    vertices: usize,
    uvs: Option<&[[f32; 2]]>,
    normals: Option<&[[f32; 3]]>,
) -> Result<Option<Attributes>> {
    let Some(w) = args.attribute_weights else {
        return Ok(None);
    };
    if args.quadric != QuadricArg::Stored || args.placement != PlacementArg::Subset {
        bail!("--attribute-weights needs --quadric stored --placement subset");
    }
    let uvs = uvs.filter(|u| u.len() == vertices);
    let normals = normals.filter(|n| n.len() == vertices);
    if w.uv > 0.0 && uvs.is_none() {
        eprintln!("note: {label}: no texture coordinates: the uv weight is not used");
    }
    if w.normal > 0.0 && normals.is_none() {
        eprintln!("note: {label}: no normals: the normal weight is not used");
    }
    let mut values = vec![[0.0; ATTRIBUTES]; vertices];
    for (i, v) in values.iter_mut().enumerate() {
        if let Some([a, b]) = uvs.and_then(|u| u.get(i)) {
            v[0] = *a;
            v[1] = *b;
        }
        if let Some([x, y, z]) = normals.and_then(|n| n.get(i)) {
            v[2] = *x;
            v[3] = *y;
            v[4] = *z;
        }
    }
    let (wu, wn) = (
        if uvs.is_some() { w.uv } else { 0.0 },
        if normals.is_some() { w.normal } else { 0.0 },
    );
    Ok(Some(Attributes {
        values,
        weights: [wu, wu, wn, wn, wn],
    }))
}

/// Primitive `p`'s `NORMAL` stream as floats, one per vertex (float accessors only).
pub(super) fn gltf_normals(p: &crate::io::gltf::Primitive) -> Option<Vec<[f32; 3]>> {
    let s = p.attributes.iter().find(|s| s.semantic == "NORMAL")?;
    if s.component_type != 5126 || s.ty != "VEC3" {
        return None;
    }
    (0..p.positions.len())
        .map(|i| {
            let e = s.data.get(i * s.elem..i * s.elem + 12)?;
            let f =
                |k: usize| f32::from_le_bytes([e[4 * k], e[4 * k + 1], e[4 * k + 2], e[4 * k + 3]]);
            Some([f(0), f(1), f(2)])
        })
        .collect()
}

/// OBJ group `g`'s normals, one per vertex, when every vertex has one.
pub(super) fn obj_normals(file: &crate::io::objattr::ObjFile, g: usize) -> Option<Vec<[f32; 3]>> {
    file.groups
        .get(g)?
        .vertices
        .iter()
        .map(|c| {
            let text = file.vn_text.get(c.2? as usize)?;
            let mut it = text.split_whitespace().map(str::parse::<f32>);
            Some([it.next()?.ok()?, it.next()?.ok()?, it.next()?.ok()?])
        })
        .collect()
}

/// With `--attribute-weights`: meshoptimizer's `simplifyWithAttributes` with the same
/// attributes and weights at the result's triangle count, its UV stretch and texture
/// deviation (as text for the part's line, and into `json` as `meshopt_attributes`).
/// Nothing without the `meshopt` feature.
#[cfg(not(feature = "meshopt"))]
pub(super) fn meshopt_reference(
    _: &crate::io::MeshData,
    _: &[[f32; 2]],
    _: &crate::io::MeshData,
    _: &Option<Attributes>,
    _: &mut serde_json::Value,
) -> String {
    String::new()
}

/// With `--attribute-weights`: meshoptimizer's `simplifyWithAttributes` with the same
/// attributes and weights at the result's triangle count, its UV stretch and texture
/// deviation (as text for the part's line, and into `json` as `meshopt_attributes`).
#[cfg(feature = "meshopt")]
pub(super) fn meshopt_reference(
    mesh: &crate::io::MeshData,
    uvs: &[[f32; 2]],
    result: &crate::io::MeshData,
    attributes: &Option<Attributes>,
    json: &mut serde_json::Value,
) -> String {
    let Some(a) = attributes else {
        return String::new();
    };
    let theirs = crate::meshopt::meshopt_simplify_with_attributes(
        mesh,
        result.triangles.len(),
        &a.values,
        &a.weights,
    );
    let stretch = crate::uvstretch::l2_stretch(&mesh.positions, uvs, &theirs.triangles);
    let diag = mesh.bbox_diagonal().max(f64::MIN_POSITIVE);
    let dev = crate::uvstretch::texture_deviation(
        &mesh.positions,
        uvs,
        &mesh.triangles,
        &theirs.triangles,
    )
    .map(|(mean, max, lost)| (100.0 * mean / diag, 100.0 * max / diag, lost));
    json["meshopt_attributes"] = serde_json::json!({
        "weights": a.weights,
        "triangles": theirs.triangles.len(),
        "uv_stretch": stretch,
        "texture_deviation_pct": dev.map(|d| [d.0, d.1]),
        "texture_samples_lost": dev.map(|d| d.2),
    });
    format!(
        "\n    meshoptimizer simplifyWithAttributes (same weights) at {} triangles: UV stretch \
         {}{}",
        theirs.triangles.len(),
        stretch.map_or("-".into(), |t| format!("{t:.4}")),
        dev.map_or(String::new(), |(mean, max, lost)| format!(
            ", texture deviation mean {mean:.4} % max {max:.4} %, {lost} samples lost"
        ))
    )
}

//! PLY with extra per-vertex properties (normals `nx ny nz`, colours `red green blue`, texture
//! coordinates `s t`, anything scalar or list) carried through a simplification.
//!
//! Positions and faces are read by [`crate::io`]'s reader, with all its checks; the `vertex`
//! element is then read again whole by `ply-rs-bw`. The result is written as binary little
//! endian PLY with the input's `vertex` element definition (same properties, same types, in
//! the same order) for each kept vertex in ascending input order, values as read (so
//! bit-identical), and a `face` element `list uchar int vertex_indices`. Other elements and
//! per-face properties are not carried.

use std::io::Cursor;

use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{DefaultElement, ElementDef};

use crate::io::MeshData;

/// A PLY file with its whole `vertex` element.
#[derive(Debug)]
pub struct PlyFile {
    /// Positions and triangles, as [`crate::io`] reads them.
    pub mesh: MeshData,
    /// The `vertex` element's definition.
    pub vertex_def: ElementDef,
    /// Every vertex's properties.
    pub vertices: Vec<DefaultElement>,
}

/// The `vertex` properties besides `x`, `y`, `z`, from the header alone (none when the bytes
/// are not a readable PLY header).
pub fn extra_properties(bytes: &[u8]) -> Vec<String> {
    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(Cursor::new(bytes));
    let Ok(header) = parser.read_header(&mut reader) else {
        return Vec::new();
    };
    header.elements.get("vertex").map_or(Vec::new(), |v| {
        v.properties
            .keys()
            .filter(|k| !["x", "y", "z"].contains(&k.as_str()))
            .cloned()
            .collect()
    })
}

/// Reads a PLY with its whole `vertex` element.
pub fn parse(bytes: &[u8]) -> Result<PlyFile, String> {
    // Every check of the plain reader first: counts against the file's size, indices, values.
    let mesh = crate::io::parse_bytes(bytes, "ply").map_err(|e| e.to_string())?;
    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(Cursor::new(bytes));
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| format!("PLY header: {e}"))?;
    let payload = parser
        .read_payload(&mut reader, &header)
        .map_err(|e| format!("PLY data: {e}"))?;
    let vertex_def = header
        .elements
        .get("vertex")
        .cloned()
        .ok_or("no `vertex` element")?;
    let vertices = payload.get("vertex").cloned().unwrap_or_default();
    if vertices.len() != mesh.positions.len() {
        return Err("vertex element read twice differently".into());
    }
    Ok(PlyFile {
        mesh,
        vertex_def,
        vertices,
    })
}

/// Binary PLY of `triangles` (input numbering) with the kept vertices' properties.
pub fn write(f: &PlyFile, triangles: &[[u32; 3]]) -> Result<Vec<u8>, String> {
    let (tris, old) = crate::io::gltf::compact(triangles, f.vertices.len())?;
    let vertices = old.iter().map(|&o| f.vertices[o].clone()).collect();
    crate::io::ply::encode(f.vertex_def.clone(), vertices, &tris)
}

//! PLY in (ascii and binary, via `ply-rs-bw`) and binary PLY out (see [`crate::io`]).

use std::io::Cursor;

use super::{triangulate, LoadNotes, MeshData, Parsed};

/// Bytes of one binary PLY scalar.
pub(crate) fn scalar_bytes(t: &ply_rs_bw::ply::ScalarType) -> usize {
    use ply_rs_bw::ply::ScalarType::*;
    match t {
        Char | UChar => 1,
        Short | UShort => 2,
        Int | UInt | Float => 4,
        Double => 8,
    }
}

pub(crate) fn parse_ply(bytes: &[u8]) -> Parsed {
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
    let mut notes = LoadNotes::default();
    for e in header.elements.values() {
        let keep: &[&str] = match e.name.as_str() {
            "vertex" => &["x", "y", "z"],
            "face" => &["vertex_indices", "vertex_index"],
            _ => {
                notes.dropped.push(format!("element `{}`", e.name));
                continue;
            }
        };
        let extra: Vec<&str> = e
            .properties
            .keys()
            .map(String::as_str)
            .filter(|k| !keep.contains(k))
            .collect();
        if !extra.is_empty() {
            notes
                .dropped
                .push(format!("{} properties {}", e.name, extra.join(", ")));
        }
    }
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
        match idx[..] {
            [a, b, c] => mesh.triangles.push([a, b, c]),
            _ if idx.len() > 3 => {
                // Indices are checked against the vertex count by `validate` afterwards;
                // `triangulate` puts out-of-range ones at the origin meanwhile.
                let split = triangulate(&mesh.positions, &idx);
                notes.polygons_split += 1;
                notes.triangles_from_polygons += split.len();
                mesh.triangles.extend(split);
            }
            _ => {
                return Err(format!(
                    "PLY face {i} has {} corners; a face needs at least 3",
                    idx.len()
                ))
            }
        }
    }
    Ok((mesh, notes))
}

pub(crate) fn ply_bytes(mesh: &MeshData) -> std::result::Result<Vec<u8>, String> {
    use ply_rs_bw::ply::{
        Addable, DefaultElement, ElementDef, Property, PropertyDef, PropertyType, ScalarType,
    };

    let mut vdef = ElementDef::new("vertex".into());
    for k in ["x", "y", "z"] {
        vdef.properties.add(PropertyDef::new(
            k.into(),
            PropertyType::Scalar(ScalarType::Float),
        ));
    }
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
    encode(vdef, vertices, &mesh.triangles)
}

/// Binary little-endian PLY of a `vertex` element as given and a `face` element of
/// `triangles` (the writer of both the positions-only file and one with its properties kept).
pub(crate) fn encode(
    vertex_def: ply_rs_bw::ply::ElementDef,
    vertices: Vec<ply_rs_bw::ply::DefaultElement>,
    triangles: &[[u32; 3]],
) -> std::result::Result<Vec<u8>, String> {
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
    ply.header.elements.add(vertex_def);
    let mut fdef = ElementDef::new("face".into());
    fdef.properties.add(PropertyDef::new(
        "vertex_indices".into(),
        PropertyType::List(ScalarType::UChar, ScalarType::Int),
    ));
    ply.header.elements.add(fdef);
    let mut faces = Vec::with_capacity(triangles.len());
    for t in triangles {
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

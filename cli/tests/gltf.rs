//! glTF and OBJ with attributes through `simplify`: files built here (a grid split on a UV
//! seam with normals, colours and a texture, a second interleaved primitive, a non-indexed
//! one, a node transform, extras), simplified, written, and read back by the `gltf` crate and
//! by a second reader of our own; every kept vertex's attributes must be bit-identical to an
//! input vertex's. Malformed files must give errors, never panics or huge allocations.

use std::collections::HashSet;
use std::process::Command;

use serde_json::{json, Value};
use tinydecimate_cli::gltf::{parse, write, GltfFile};

/// Accessors, views and one binary buffer, built up in order.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(s) = stride {
            v["byteStride"] = json!(s);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    fn accessor(&mut self, view: usize, offset: usize, ct: u32, ty: &str, count: usize) -> usize {
        self.accessors.push(json!({
            "bufferView": view, "byteOffset": offset, "componentType": ct, "count": count, "type": ty
        }));
        self.accessors.len() - 1
    }

    fn floats(&mut self, data: &[f32], ty: &str, n: usize) -> usize {
        let b: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let v = self.view(&b, None);
        let a = self.accessor(v, 0, 5126, ty, data.len() / n);
        if ty == "VEC3" && n == 3 {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in data.chunks(3) {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            self.accessors[a]["min"] = json!(lo);
            self.accessors[a]["max"] = json!(hi);
        }
        a
    }
}

/// A grid of `n`x`n` quads split on a UV seam down its middle column: the seam's vertices are
/// doubled (u jumps by 1 across it), as an exporter splits them.
#[allow(clippy::needless_range_loop)]
fn seam_grid(n: usize) -> (Vec<f32>, Vec<f32>, Vec<u32>) {
    let mut pos = Vec::new();
    let mut uv = Vec::new();
    let mut id = vec![[0u32; 2]; (n + 1) * (n + 1)];
    let mid = n / 2;
    for y in 0..=n {
        for x in 0..=n {
            let z = ((x * 7 + y * 3) % 5) as f32 * 0.02;
            let copies = if x == mid { 2 } else { 1 };
            for c in 0..copies {
                id[y * (n + 1) + x][c] = (pos.len() / 3) as u32;
                pos.extend_from_slice(&[x as f32 / n as f32, y as f32 / n as f32, z]);
                let shift = if x > mid || c == 1 { 1.0 } else { 0.0 };
                uv.extend_from_slice(&[x as f32 / n as f32 + shift, y as f32 / n as f32]);
            }
            if copies == 1 {
                id[y * (n + 1) + x][1] = id[y * (n + 1) + x][0];
            }
        }
    }
    let mut idx = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let side = usize::from(x >= mid);
            let v = |xx: usize, yy: usize| id[yy * (n + 1) + xx][side];
            idx.extend_from_slice(&[v(x, y), v(x + 1, y), v(x + 1, y + 1)]);
            idx.extend_from_slice(&[v(x, y), v(x + 1, y + 1), v(x, y + 1)]);
        }
    }
    (pos, uv, idx)
}

/// The test document: three primitives in two meshes, a node transform, a textured material,
/// extras. Returns the JSON and the binary buffer.
fn document() -> (Value, Vec<u8>) {
    let mut b = Builder::default();
    // Primitive A: the seam grid, u16 indices, POSITION, NORMAL, TEXCOORD_0, COLOR_0 (u8).
    let (pos, uv, idx) = seam_grid(12);
    let nv = pos.len() / 3;
    let pa = b.floats(&pos, "VEC3", 3);
    let normals: Vec<f32> = (0..nv)
        .flat_map(|i| [0.0, (i as f32) * 1e-3, 1.0])
        .collect();
    let na = b.floats(&normals, "VEC3", 3);
    let ta = b.floats(&uv, "VEC2", 2);
    let colors: Vec<u8> = (0..nv)
        .flat_map(|i| [i as u8, (i * 3) as u8, 7, 255])
        .collect();
    let cv = b.view(&colors, None);
    let ca = b.accessor(cv, 0, 5121, "VEC4", nv);
    b.accessors[ca]["normalized"] = json!(true);
    let ib: Vec<u8> = idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect();
    let iv = b.view(&ib, None);
    let ia = b.accessor(iv, 0, 5123, "SCALAR", idx.len());

    // Primitive B: a 6x6 grid, POSITION and NORMAL interleaved (stride 24), u8 indices.
    let m = 6;
    let mut inter = Vec::new();
    for y in 0..=m {
        for x in 0..=m {
            for f in [
                x as f32,
                y as f32,
                ((x * y) % 3) as f32 * 0.1,
                0.0,
                0.0,
                1.0,
            ] {
                inter.extend_from_slice(&f.to_le_bytes());
            }
        }
    }
    let vv = b.view(&inter, Some(24));
    let nb = (m + 1) * (m + 1);
    let pb = b.accessor(vv, 0, 5126, "VEC3", nb);
    b.accessors[pb]["min"] = json!([0.0, 0.0, 0.0]);
    b.accessors[pb]["max"] = json!([m as f32, m as f32, 0.2]);
    let nbn = b.accessor(vv, 12, 5126, "VEC3", nb);
    let mut ib8 = Vec::new();
    for y in 0..m {
        for x in 0..m {
            let v = (y * (m + 1) + x) as u8;
            let w = (m + 1) as u8;
            ib8.extend_from_slice(&[v, v + 1, v + w + 1, v, v + w + 1, v + w]);
        }
    }
    let ivb = b.view(&ib8, None);
    let ib_acc = b.accessor(ivb, 0, 5121, "SCALAR", ib8.len());

    // Primitive C: not indexed, one quad.
    let quad = [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0,
    ];
    let pc = b.floats(&quad, "VEC3", 3);

    let json = json!({
        "asset": {"version": "2.0", "generator": "tinydecimate test"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"mesh": 0, "translation": [1.0, 2.0, 3.0], "rotation": [0.0, 0.0, 0.70710677, 0.70710677],
             "extras": {"keep": "me"}},
            {"mesh": 1, "scale": [2.0, 2.0, 2.0], "name": "second"}
        ],
        "meshes": [
            {"primitives": [
                {"attributes": {"POSITION": pa, "NORMAL": na, "TEXCOORD_0": ta, "COLOR_0": ca},
                 "indices": ia, "material": 0, "extras": {"part": "A"}},
                {"attributes": {"POSITION": pc}}
            ]},
            {"primitives": [{"attributes": {"POSITION": pb, "NORMAL": nbn}, "indices": ib_acc, "mode": 4}]}
        ],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "name": "checker"}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729}],
        "images": [{"uri": "checker.png"}],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": b.bin.len()}],
        "extras": {"author": "test"}
    });
    (json, b.bin)
}

fn glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((12 + 8 + j.len() + 8 + b.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// Every vertex of every primitive as the `gltf` crate reads it: the primitive's label and
/// the bits of position, normal, uv and colour.
type Vertex = (
    usize,
    [u32; 3],
    Option<[u32; 3]>,
    Option<[u32; 2]>,
    Option<[u8; 4]>,
);

/// Reads with the `gltf` crate (validation, then its accessor reader over the BIN chunk):
/// each primitive's vertices and triangle count, in mesh order.
fn read_with_gltf_crate(bytes: &[u8]) -> Vec<(Vec<Vertex>, Vec<u32>)> {
    let g = gltf::Gltf::from_slice(bytes).expect("the gltf crate reads the output");
    let blob = g.blob.clone().expect("a BIN chunk");
    let mut out = Vec::new();
    let mut k = 0;
    for mesh in g.document.meshes() {
        for p in mesh.primitives() {
            let r = p.reader(|b| (b.index() == 0).then_some(&blob[..]));
            let pos: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
            let nrm: Option<Vec<[f32; 3]>> = r.read_normals().map(|n| n.collect());
            let uv: Option<Vec<[f32; 2]>> = r.read_tex_coords(0).map(|t| t.into_f32().collect());
            let col: Option<Vec<[u8; 4]>> = r.read_colors(0).map(|c| c.into_rgba_u8().collect());
            let idx: Vec<u32> = match r.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..pos.len() as u32).collect(),
            };
            let verts = (0..pos.len())
                .map(|i| {
                    (
                        k,
                        pos[i].map(f32::to_bits),
                        nrm.as_ref().map(|n| n[i].map(f32::to_bits)),
                        uv.as_ref().map(|t| t[i].map(f32::to_bits)),
                        col.as_ref().map(|c| c[i]),
                    )
                })
                .collect();
            out.push((verts, idx));
            k += 1;
        }
    }
    out
}

/// The second reader: JSON by serde_json, GLB chunks and accessor ranges checked by hand.
fn check_ranges_by_hand(bytes: &[u8]) -> Value {
    assert_eq!(&bytes[..4], b"glTF");
    let u = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(u(4), 2);
    assert_eq!(u(8), bytes.len());
    let jl = u(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(jl % 4, 0);
    let json: Value = serde_json::from_slice(&bytes[20..20 + jl]).unwrap();
    let bl = u(20 + jl);
    assert_eq!(&bytes[24 + jl..28 + jl], b"BIN\0");
    assert_eq!(28 + jl + bl, bytes.len());
    let bin = &bytes[28 + jl..];
    let buffers = json["buffers"].as_array().unwrap();
    assert_eq!(buffers.len(), 1);
    let blen = buffers[0]["byteLength"].as_u64().unwrap() as usize;
    assert!(blen <= bin.len() && bin.len() - blen < 4);
    let views = json["bufferViews"].as_array().unwrap();
    for v in views {
        let end = v["byteOffset"].as_u64().unwrap_or(0) + v["byteLength"].as_u64().unwrap();
        assert!(end as usize <= blen, "view {v} past the buffer");
    }
    for a in json["accessors"].as_array().unwrap() {
        let v = &views[a["bufferView"].as_u64().unwrap() as usize];
        let csize = match a["componentType"].as_u64().unwrap() {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        let n = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            t => panic!("type {t}"),
        };
        let elem = csize * n;
        let stride = v["byteStride"].as_u64().map_or(elem, |s| s as usize);
        let count = a["count"].as_u64().unwrap() as usize;
        let off = a["byteOffset"].as_u64().unwrap_or(0) as usize;
        assert!(count > 0);
        assert!(off + stride * (count - 1) + elem <= v["byteLength"].as_u64().unwrap() as usize);
        assert_eq!(
            (v["byteOffset"].as_u64().unwrap_or(0) as usize + off) % csize,
            0
        );
    }
    // POSITION's min and max are those of its data.
    for m in json["meshes"].as_array().unwrap() {
        for p in m["primitives"].as_array().unwrap() {
            let a = &json["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize];
            let v = &views[a["bufferView"].as_u64().unwrap() as usize];
            let start = v["byteOffset"].as_u64().unwrap_or(0) as usize
                + a["byteOffset"].as_u64().unwrap_or(0) as usize;
            let stride = v["byteStride"].as_u64().map_or(12, |s| s as usize);
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for i in 0..a["count"].as_u64().unwrap() as usize {
                for k in 0..3 {
                    let at = start + i * stride + 4 * k;
                    let x = f32::from_le_bytes(bin[at..at + 4].try_into().unwrap());
                    lo[k] = lo[k].min(x);
                    hi[k] = hi[k].max(x);
                }
            }
            assert_eq!(a["min"], json!(lo));
            assert_eq!(a["max"], json!(hi));
        }
    }
    json
}

fn simplify_all(file: &GltfFile, ratio: f32) -> Vec<Vec<[u32; 3]>> {
    let config = tinydecimate::Config::new().with_ratio(ratio);
    file.primitives
        .iter()
        .map(|p| {
            let mesh = tinydecimate_cli::io::MeshData {
                positions: p.positions.clone(),
                triangles: p.triangles.clone(),
            };
            tinydecimate_cli::simplify::simplify(&mesh, &config)
                .unwrap()
                .0
                .triangles
        })
        .collect()
}

#[test]
fn glb_round_trip_keeps_every_attribute_bit_for_bit() {
    let (json, bin) = document();
    let input = glb(&json, &bin);
    let file = parse(&input, None).unwrap();
    assert_eq!(file.primitives.len(), 3);
    let results = simplify_all(&file, 0.25);
    // The grid really was simplified.
    assert!(results[0].len() < file.primitives[0].triangles.len() / 2);
    assert!(results[2].len() < file.primitives[2].triangles.len() / 2);
    let (out, bin_out) = write(&file, &results, true, "unused.bin").unwrap();
    assert!(bin_out.is_none());

    let before = read_with_gltf_crate(&input);
    let after = read_with_gltf_crate(&out);
    assert_eq!(after.len(), before.len());
    // Primitive order in the crate's reading: mesh 0 (A, C), mesh 1 (B); results follow
    // file.primitives, which is the same order.
    for (k, ((vin, _), (vout, iout))) in before.iter().zip(&after).enumerate() {
        let known: HashSet<&Vertex> = vin.iter().collect();
        for v in vout {
            assert!(
                known.contains(v),
                "primitive {k}: vertex {v:?} is not an input vertex"
            );
        }
        assert_eq!(
            iout.len(),
            results[k].len() * 3,
            "primitive {k}: triangle count"
        );
        // Unused vertices dropped: every output vertex is used.
        let used: HashSet<u32> = iout.iter().copied().collect();
        assert_eq!(
            used.len(),
            vout.len(),
            "primitive {k}: unused vertices kept"
        );
        // The same triangles, vertex by vertex, as the library's result.
        let p = &file.primitives[k];
        for (t, tri) in results[k].iter().enumerate() {
            for c in 0..3 {
                let want = &vin[tri[c] as usize];
                let got = &vout[iout[3 * t + c] as usize];
                assert_eq!(want, got, "primitive {k} triangle {t}");
            }
        }
        assert_eq!(p.attributes.len(), file.primitives[k].attributes.len());
    }

    let j = check_ranges_by_hand(&out);
    // Passed through untouched.
    for key in [
        "asset",
        "scene",
        "scenes",
        "nodes",
        "materials",
        "textures",
        "samplers",
        "images",
        "extras",
    ] {
        assert_eq!(j[key], json[key], "{key}");
    }
    assert_eq!(j["meshes"][0]["primitives"][0]["material"], json!(0));
    assert_eq!(
        j["meshes"][0]["primitives"][0]["extras"],
        json!({"part": "A"})
    );
    // Only the new accessors are left (3 + 1 + 1 indices and attributes), and their views.
    assert_eq!(j["accessors"].as_array().unwrap().len(), 5 + 2 + 3);
    assert!(out.len() < input.len());

    // Read back by our own reader: the same vertices as the crate saw.
    let again = parse(&out, None).unwrap();
    for (p, (vout, _)) in again.primitives.iter().zip(&after) {
        assert_eq!(p.positions.len(), vout.len());
    }
}

#[test]
fn gltf_with_bin_beside_it_reads_back_the_same() {
    let (json, bin) = document();
    let file = parse(&glb(&json, &bin), None).unwrap();
    let results = simplify_all(&file, 0.25);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out model.gltf");
    tinydecimate_cli::gltf::save(&path, &file, &results).unwrap();
    let text: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(text["buffers"][0]["uri"], json!("out model.bin"));
    let back = tinydecimate_cli::gltf::load(&path).unwrap();
    let (glb_bytes, _) = write(&file, &results, true, "").unwrap();
    let via_glb = parse(&glb_bytes, None).unwrap();
    assert_eq!(back.primitives, via_glb.primitives);
    // A data: URI buffer reads like the BIN chunk.
    use base64::Engine as _;
    let mut embedded = json.clone();
    embedded["buffers"][0]["uri"] = json!(format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    ));
    let e = parse(&serde_json::to_vec(&embedded).unwrap(), None).unwrap();
    assert_eq!(e.primitives, file.primitives);
}

fn err(json: &Value, bin: &[u8]) -> String {
    match parse(&glb(json, bin), None) {
        Ok(_) => panic!("accepted: {json}"),
        Err(e) => e,
    }
}

#[test]
fn malformed_files_get_clear_errors() {
    let (json, bin) = document();
    // A missing accessor.
    let mut j = json.clone();
    j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(99);
    assert!(err(&j, &bin).contains("accessor 99"), "{}", err(&j, &bin));
    // An index past the vertices.
    let mut b = bin.clone();
    let ia = json["meshes"][0]["primitives"][0]["indices"]
        .as_u64()
        .unwrap() as usize;
    let view = json["accessors"][ia]["bufferView"].as_u64().unwrap() as usize;
    let at = json["bufferViews"][view]["byteOffset"].as_u64().unwrap() as usize;
    b[at..at + 2].copy_from_slice(&60000u16.to_le_bytes());
    assert!(err(&json, &b).contains("past the"), "{}", err(&json, &b));
    // Huge counts: refused before anything of that size is allocated (4 G elements of 12
    // bytes would abort the test).
    for count in [u32::MAX as u64, 1 << 40, 100_000] {
        let mut j = json.clone();
        j["accessors"][0]["count"] = json!(count);
        let e = err(&j, &bin);
        assert!(e.contains("do not fit"), "{e}");
    }
    // A view past its buffer, a stride below the element, a sparse accessor.
    let mut j = json.clone();
    j["bufferViews"][0]["byteLength"] = json!(1 << 30);
    assert!(!err(&j, &bin).is_empty());
    let mut j = json.clone();
    j["bufferViews"][0]["byteStride"] = json!(8);
    assert!(err(&j, &bin).contains("byteStride"));
    let mut j = json.clone();
    j["accessors"][0]["sparse"] = json!({"count": 1, "indices": {"bufferView": 0, "componentType": 5125}, "values": {"bufferView": 0}});
    assert!(err(&j, &bin).contains("sparse"));
    // POSITION not float VEC3, corners not a multiple of 3.
    let mut j = json.clone();
    j["accessors"][0]["componentType"] = json!(5123);
    assert!(err(&j, &bin).contains("only float VEC3"));
    let mut j = json.clone();
    j["accessors"][ia]["count"] = json!(json["accessors"][ia]["count"].as_u64().unwrap() - 1);
    assert!(err(&j, &bin).contains("multiple of 3"));
    // A non-finite position (its min/max could not be written).
    let mut b = bin.clone();
    b[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(err(&json, &b).contains("non-finite"), "{}", err(&json, &b));
    // Attributes of different counts.
    let mut j = json.clone();
    let na = json["meshes"][0]["primitives"][0]["attributes"]["NORMAL"]
        .as_u64()
        .unwrap() as usize;
    j["accessors"][na]["count"] = json!(3);
    assert!(err(&j, &bin).contains("elements, POSITION"));
    // A missing buffer: an external file where none can be read, a file that is not there,
    // a GLB without its BIN chunk.
    let mut j = json.clone();
    j["buffers"][0]["uri"] = json!("missing.bin");
    let text = serde_json::to_vec(&j).unwrap();
    assert!(parse(&text, None).unwrap_err().contains("not available"));
    let dir = tempfile::tempdir().unwrap();
    assert!(parse(&text, Some(dir.path()))
        .unwrap_err()
        .contains("cannot read"));
    let short = glb(&json, &[]);
    let no_bin = &short[..short.len() - 8];
    let mut no_bin = no_bin.to_vec();
    let l = no_bin.len() as u32;
    no_bin[8..12].copy_from_slice(&l.to_le_bytes());
    assert!(parse(&no_bin, None).is_err());
    // Draco compression is named.
    let mut j = json.clone();
    j["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    j["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    assert!(err(&j, &bin).contains("Draco") || err(&j, &bin).contains("draco"));
}

#[test]
fn every_truncation_and_header_lie_is_an_error() {
    let (json, bin) = document();
    let good = glb(&json, &bin);
    for len in 0..good.len() {
        assert!(
            parse(&good[..len], None).is_err(),
            "prefix of {len} bytes accepted"
        );
    }
    // A header or chunk claiming more than the file holds.
    for (at, v) in [(8, u32::MAX), (8, 3), (12, u32::MAX), (4, 1)] {
        let mut b = good.clone();
        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        assert!(parse(&b, None).is_err());
    }
    let jl = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
    let mut b = good.clone();
    b[20 + jl..24 + jl].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = parse(&b, None).unwrap_err();
    assert!(e.contains("truncated"), "{e}");
}

#[test]
fn simplify_command_writes_glb_and_refuses_optimal_placement() {
    let dir = tempfile::tempdir().unwrap();
    let (json, bin) = document();
    let input = dir.path().join("in.glb");
    std::fs::write(&input, glb(&json, &bin)).unwrap();
    let output = dir.path().join("out.glb");
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_tinydecimate"))
            .arg("simplify")
            .arg(&input)
            .arg(&output)
            .args(args)
            .output()
            .unwrap()
    };
    let o = run(&["--ratio", "0.25"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // Mesh 0's two primitives are one run; mesh 1 is its own.
    assert!(
        text.contains("mesh 0 (2 primitives)")
            && text.contains("mesh 1 primitive 0")
            && text.contains("valid"),
        "{text}"
    );
    assert!(!text.contains("NOT valid"), "{text}");
    let out = std::fs::read(&output).unwrap();
    assert!(gltf::Gltf::from_slice(&out).is_ok());
    check_ranges_by_hand(&out);
    let o = run(&[
        "--ratio",
        "0.25",
        "--quadric",
        "stored",
        "--placement",
        "optimal",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("optimal placement moves vertices"));
    // OBJ in, glTF out: refused with the reason (glTF in, OBJ out is written:
    // `simplify_glb_to_obj_ply_stl_writes_the_geometry`).
    let obj = dir.path().join("x.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_tinydecimate"))
        .args(["simplify"])
        .arg(&obj)
        .arg(dir.path().join("x.glb"))
        .args(["--ratio", "0.5"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("glTF is written only from glTF"));
}

/// `--attribute-weights`: the attribute-aware stored quadric runs on a glTF and prints
/// meshoptimizer's `simplifyWithAttributes` beside it; refused without `--quadric stored`, with
/// a name other than uv and normal, and on a mesh without attributes.
#[test]
fn simplify_command_takes_attribute_weights() {
    let dir = tempfile::tempdir().unwrap();
    let (json, bin) = document();
    let input = dir.path().join("in.glb");
    std::fs::write(&input, glb(&json, &bin)).unwrap();
    let run = |input: &std::path::Path, output: &str, args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_tinydecimate"))
            .arg("simplify")
            .arg(input)
            .arg(dir.path().join(output))
            .args(["--ratio", "0.25"])
            .args(args)
            .output()
            .unwrap()
    };
    let o = run(
        &input,
        "out.glb",
        &[
            "--quadric",
            "stored",
            "--attribute-weights",
            "uv=10,normal=1",
            "--measure",
            // Mesh 0's quad has no texture coordinates: on its own, primitive 0 has them.
            "--per-primitive",
        ],
    );
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // meshoptimizer's figures beside ours: feature `meshopt` (on in the workspace's build).
    if cfg!(feature = "meshopt") {
        assert!(text.contains("simplifyWithAttributes"), "{text}");
    }
    assert!(
        text.contains("valid") && !text.contains("NOT valid"),
        "{text}"
    );
    let o = run(&input, "out.glb", &["--attribute-weights", "uv=10"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs --quadric stored"));
    let o = run(
        &input,
        "out.glb",
        &["--quadric", "stored", "--attribute-weights", "colour=1"],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("uv and normal"));
    let plain = dir.path().join("plain.obj");
    std::fs::write(
        &plain,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
    )
    .unwrap();
    let o = run(
        &plain,
        "out.obj",
        &["--quadric", "stored", "--attribute-weights", "uv=1"],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs vertex attributes"));
}

#[test]
fn obj_keeps_texture_coordinates_normals_and_materials() {
    // The seam grid as OBJ: positions shared across the seam, texture coordinates split.
    let n = 10;
    let mut s = String::from("mtllib grid.mtl\n");
    for y in 0..=n {
        for x in 0..=n {
            s += &format!(
                "v {} {} {} 0.5 0.25 1\n",
                x as f32 / n as f32,
                y,
                ((x * 7 + y * 3) % 5) as f32 * 0.02
            );
        }
    }
    for y in 0..=n {
        for x in 0..=n {
            s += &format!("vt {} {}\n", x as f32 / n as f32, y as f32 / n as f32);
        }
    }
    // The seam's second texture coordinates.
    for y in 0..=n {
        s += &format!("vt 1.{} {}\n", y, y as f32 / n as f32);
    }
    s += "vn 0 0 1\nvn 0 0.1 0.99\n";
    let vt_seam = (n + 1) * (n + 1);
    for (mat, rows) in [("left", 0..n / 2), ("right", n / 2..n)] {
        s += &format!("usemtl {mat}\n");
        for y in rows {
            for x in 0..n {
                let v = |xx: usize, yy: usize| yy * (n + 1) + xx + 1;
                let t = |xx: usize, yy: usize| {
                    if xx == n / 2 && x >= n / 2 {
                        vt_seam + yy + 1
                    } else {
                        v(xx, yy)
                    }
                };
                let c = |xx: usize, yy: usize| {
                    format!("{}/{}/{}", v(xx, yy), t(xx, yy), 1 + (xx + yy) % 2)
                };
                // A quad: the reader splits it.
                s += &format!(
                    "f {} {} {} {}\n",
                    c(x, y),
                    c(x + 1, y),
                    c(x + 1, y + 1),
                    c(x, y + 1)
                );
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("grid.obj");
    std::fs::write(&input, &s).unwrap();
    let output = dir.path().join("out.obj");
    let o = Command::new(env!("CARGO_BIN_EXE_tinydecimate"))
        .arg("simplify")
        .arg(&input)
        .arg(&output)
        .args(["--ratio", "0.3"])
        .output()
        .unwrap();
    let report = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{report}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // One OBJ, one run: both groups together.
    assert!(report.contains("all 2 material groups"), "{report}");
    assert!(report.contains("0 of them new"), "{report}");
    let out = std::fs::read_to_string(&output).unwrap();
    assert!(out.starts_with("mtllib grid.mtl\n"));
    assert!(out.contains("usemtl left\n") && out.contains("usemtl right\n"));
    // Every output corner's (v, vt, vn) text is an input corner's.
    let corners = |text: &str| -> Vec<(String, String, String)> {
        let (mut v, mut t, mut nn) = (vec![], vec![], vec![]);
        let mut out = vec![];
        for l in text.lines() {
            let (k, rest) = l.split_once(' ').unwrap_or((l, ""));
            match k {
                "v" => v.push(rest.to_string()),
                "vt" => t.push(rest.to_string()),
                "vn" => nn.push(rest.to_string()),
                "f" => {
                    for c in rest.split_whitespace() {
                        let i: Vec<usize> = c.split('/').map(|x| x.parse().unwrap()).collect();
                        out.push((
                            v[i[0] - 1].clone(),
                            t[i[1] - 1].clone(),
                            nn[i[2] - 1].clone(),
                        ));
                    }
                }
                _ => {}
            }
        }
        out
    };
    let inputs: HashSet<_> = corners(&s).into_iter().collect();
    let outputs = corners(&out);
    assert!(
        outputs.len() / 3 < 2 * n * n / 2,
        "not simplified: {} triangles",
        outputs.len() / 3
    );
    for c in &outputs {
        assert!(inputs.contains(c), "{c:?} is not an input corner");
    }
    // tobj, an independent reader, reads the output with the same counts.
    let (models, _) = tobj::load_obj(
        &output,
        &tobj::LoadOptions {
            triangulate: false,
            ..Default::default()
        },
    )
    .unwrap();
    let faces: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    assert_eq!(faces, outputs.len() / 3);
    assert!(models
        .iter()
        .all(|m| !m.mesh.texcoords.is_empty() && !m.mesh.normals.is_empty()));
}

/// What the fuzz target `gltf` checks, on mutations of the test file: no panic; read files
/// write and read back with the same attribute bytes per corner.
fn round_trip(data: &[u8]) -> bool {
    let Ok(file) = parse(data, None) else {
        return false;
    };
    for p in &file.primitives {
        let n = p.positions.len();
        assert!(p.triangles.iter().flatten().all(|&i| (i as usize) < n));
        for s in p.attributes.iter().chain(p.targets.iter().flatten()) {
            assert_eq!(s.count(), n, "{}", s.semantic);
        }
    }
    let results: Vec<Vec<[u32; 3]>> = file
        .primitives
        .iter()
        .map(|p| p.triangles.clone())
        .collect();
    let (out, _) = write(&file, &results, true, "").expect("writes what it read");
    let again = parse(&out, None).expect("reads what it wrote");
    assert_eq!(again.primitives.len(), file.primitives.len());
    for (a, b) in file.primitives.iter().zip(&again.primitives) {
        assert_eq!(a.triangles.len(), b.triangles.len());
        for (sa, sb) in a.attributes.iter().zip(&b.attributes) {
            assert_eq!(sa.semantic, sb.semantic);
            for (ta, tb) in a.triangles.iter().zip(&b.triangles) {
                for k in 0..3 {
                    assert_eq!(sa.element(ta[k] as usize), sb.element(tb[k] as usize));
                }
            }
        }
    }
    true
}

#[test]
fn mutated_files_never_panic() {
    use rand::{RngExt, SeedableRng};
    let (json, bin) = document();
    let good = glb(&json, &bin);
    assert!(round_trip(&good));
    let mut read = 0;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    for _ in 0..3000 {
        let mut b = good.clone();
        for _ in 0..rng.random_range(1..8) {
            let at = rng.random_range(0..b.len());
            b[at] = rng.random();
        }
        read += usize::from(round_trip(&b));
    }
    // The JSON text mutated: digits changed in place.
    let text = serde_json::to_string(&json).unwrap();
    let digits: Vec<usize> = text
        .bytes()
        .enumerate()
        .filter(|(_, c)| c.is_ascii_digit())
        .map(|(i, _)| i)
        .collect();
    for _ in 0..3000 {
        let mut t = text.clone().into_bytes();
        for _ in 0..rng.random_range(1..4) {
            let at = digits[rng.random_range(0..digits.len())];
            t[at] = b"0123456789"[rng.random_range(0..10)];
        }
        read += usize::from(round_trip(&glb(
            &serde_json::from_slice(&t).unwrap_or(json!({})),
            &bin,
        )));
    }
    // Enough mutants were read (and so written and read back) for the test to mean something.
    assert!(read > 500, "only {read} mutants read");
}

#[test]
fn ply_keeps_extra_vertex_properties() {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::DefaultElement;
    let n = 10;
    let mut s = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nproperty float nx\nproperty uchar red\nproperty float s\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        (n + 1) * (n + 1),
        n * n
    );
    for y in 0..=n {
        for x in 0..=n {
            s += &format!(
                "{x} {y} {} 0.{x}{y} {} {}.5\n",
                (x * y) % 3,
                (x * 11 + y) % 256,
                x
            );
        }
    }
    for y in 0..n {
        for x in 0..n {
            let v = y * (n + 1) + x;
            s += &format!("4 {} {} {} {}\n", v, v + 1, v + n + 2, v + n + 1);
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("grid.ply");
    std::fs::write(&input, &s).unwrap();
    let output = dir.path().join("out.ply");
    let o = Command::new(env!("CARGO_BIN_EXE_tinydecimate"))
        .arg("simplify")
        .arg(&input)
        .arg(&output)
        // Heights jump by up to 2 between neighbours: every collapse is over the default
        // error limit, and this test is about the vertex properties.
        .args(["--ratio", "0.3", "--error-limit", "none"])
        .output()
        .unwrap();
    let report = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{report}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(report.contains("nx, red, s kept"), "{report}");
    let read = |bytes: &[u8]| {
        Parser::<DefaultElement>::new()
            .read_ply(&mut std::io::Cursor::new(bytes))
            .unwrap()
    };
    let a = read(s.as_bytes());
    let b = read(&std::fs::read(&output).unwrap());
    let key = |e: &DefaultElement| format!("{e:?}");
    let known: HashSet<String> = a.payload["vertex"].iter().map(key).collect();
    let kept = &b.payload["vertex"];
    assert!(kept.len() < (n + 1) * (n + 1) / 2);
    for v in kept {
        assert_eq!(v.len(), 6);
        assert!(known.contains(&key(v)), "{v:?} is not an input vertex");
    }
    let faces = &b.payload["face"];
    assert!(faces.len() < 2 * n * n / 2);
}

/// A wavy `n`x`n` grid shaded flat: every triangle has its own three vertices with its face
/// normal, and one continuous texture (u, v = x, y), as an exporter writes a flat-shaded model.
fn flat_shaded_grid(n: usize) -> Vec<u8> {
    let (mut pos, mut nrm, mut uv) = (Vec::new(), Vec::new(), Vec::new());
    let p = |x: usize, y: usize| {
        let (fx, fy) = (x as f32 / n as f32, y as f32 / n as f32);
        [fx, fy, 0.1 * (fx * 6.0).sin() * (fy * 4.0).cos()]
    };
    for y in 0..n {
        for x in 0..n {
            for t in [
                [p(x, y), p(x + 1, y), p(x + 1, y + 1)],
                [p(x, y), p(x + 1, y + 1), p(x, y + 1)],
            ] {
                let (u, v) = (
                    [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]],
                    [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]],
                );
                let c = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
                for q in t {
                    pos.extend_from_slice(&q);
                    nrm.extend(c.map(|x| x / l));
                    uv.extend_from_slice(&[q[0], q[1]]);
                }
            }
        }
    }
    let mut b = Builder::default();
    let pa = b.floats(&pos, "VEC3", 3);
    let na = b.floats(&nrm, "VEC3", 3);
    let ta = b.floats(&uv, "VEC2", 2);
    let primitive = json!({"attributes": {"POSITION": pa, "NORMAL": na, "TEXCOORD_0": ta}});
    one_mesh_glb(b, vec![primitive], json!([]))
}

/// A GLB of one node with one mesh of `primitives`, `materials` (none when empty: glTF's
/// arrays are never empty) and `b`'s accessors.
fn one_mesh_glb(b: Builder, primitives: Vec<Value>, materials: Value) -> Vec<u8> {
    let mut json = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": primitives}],
        "materials": materials,
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": b.bin.len()}],
    });
    if materials.as_array().is_some_and(Vec::is_empty) {
        json.as_object_mut().map(|o| o.remove("materials"));
    }
    glb(&json, &b.bin)
}

/// Flat shading splits every vertex into one wedge per triangle: with `--hard-edges weld` (the
/// default) the simplifier sees one continuous texture and reaches the target; with `keep`
/// every interior vertex is a seam corner of six wedges and stays, and so it does with split
/// seams. Every vertex written is an input vertex, bit for bit, and the output is valid with no
/// crack.
#[test]
fn flat_shaded_texture_simplifies_with_hard_edges_welded() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("flat.glb");
    std::fs::write(&input, flat_shaded_grid(12)).unwrap();
    let inputs: HashSet<Vertex> = read_with_gltf_crate(&std::fs::read(&input).unwrap())[0]
        .0
        .iter()
        .copied()
        .collect();
    let run = |hard_edges: &str, seams: &str| {
        let output = dir.path().join(format!("out-{hard_edges}-{seams}.glb"));
        let o = Command::new(env!("CARGO_BIN_EXE_tinydecimate"))
            .arg("simplify")
            .arg(&input)
            .arg(&output)
            .args([
                "--ratio",
                "0.25",
                "--hard-edges",
                hard_edges,
                "--seams",
                seams,
                "--measure",
            ])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(
            o.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!text.contains("NOT valid"), "{text}");
        let read = read_with_gltf_crate(&std::fs::read(&output).unwrap());
        let (verts, idx) = &read[0];
        for v in verts {
            assert!(
                inputs.contains(v),
                "{hard_edges}: vertex {v:?} is no input vertex"
            );
        }
        assert!(text.contains("0 triangles torn between charts"), "{text}");
        idx.len() / 3
    };
    let welded = run("weld", "weld");
    assert!(
        welded <= 72,
        "hard edges welded: {welded} of 288 triangles for 72"
    );
    let kept = run("keep", "weld");
    assert!(
        kept > 200,
        "hard edges kept: {kept} of 288 triangles (the seam corners stay)"
    );
    // Split seams: every split vertex is its own (hard edges are not welded), and the output
    // is a valid simplification of the file's vertices.
    let split = run("weld", "split");
    assert!(split > 200, "seams split: {split} of 288 triangles");
}

/// Runs the real binary with `args`.
fn host(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tinydecimate"))
        .args(args)
        .output()
        .unwrap()
}

fn text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The same geometry as a GLB, written as OBJ from the `gltf` crate's reading (not ours): every
/// primitive's vertices, then its triangles, numbered after the previous primitive's.
fn obj_from_gltf_crate(bytes: &[u8]) -> (String, usize) {
    let mut v = String::new();
    let mut f = String::new();
    let mut base = 0;
    let mut triangles = 0;
    for (verts, idx) in read_with_gltf_crate(bytes) {
        for (_, p, _, _, _) in &verts {
            let p = p.map(f32::from_bits);
            v += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        for t in idx.chunks(3) {
            f += &format!(
                "f {} {} {}\n",
                base + t[0] as usize + 1,
                base + t[1] as usize + 1,
                base + t[2] as usize + 1
            );
            triangles += 1;
        }
        base += verts.len();
    }
    (v + &f, triangles)
}

/// `check`, `metro`, `cluster` and `pm encode` read a GLB as `simplify` does (every triangle
/// primitive once, in its own coordinates): each prints the same as for the same geometry
/// written as OBJ, file names aside, and the triangle count `simplify` reports. Bad glTF gets
/// one line and exit code 2 from each.
#[test]
fn every_command_reads_glb_as_simplify_counts_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n);
    let (json, bin) = document();
    let bytes = glb(&json, &bin);
    std::fs::write(d("m.glb"), &bytes).unwrap();
    let (obj, triangles) = obj_from_gltf_crate(&bytes);
    std::fs::write(d("m.obj"), obj).unwrap();
    assert_eq!(triangles, 288 + 2 + 72);
    // simplify's count of the same file.
    let o = host(&[
        "simplify".as_ref(),
        d("m.glb").as_os_str(),
        d("s.glb").as_os_str(),
        "--ratio".as_ref(),
        "0.5".as_ref(),
        "--no-measure".as_ref(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains(&format!("{triangles} -> ")),
        "{}",
        text(&o)
    );
    let s = d("s.obj");
    let runs: Vec<(&str, Vec<&std::ffi::OsStr>)> = vec![
        ("check", vec!["check".as_ref(), "M".as_ref(), s.as_os_str()]),
        ("metro", vec!["metro".as_ref(), "M".as_ref(), s.as_os_str()]),
        (
            "cluster",
            vec![
                "cluster".as_ref(),
                "M".as_ref(),
                "OUT".as_ref(),
                "--target-triangles".as_ref(),
                "100".as_ref(),
            ],
        ),
        (
            "pm encode",
            vec![
                "pm".as_ref(),
                "encode".as_ref(),
                "M".as_ref(),
                "OUT".as_ref(),
            ],
        ),
    ];
    // A simplified mesh to compare with, from the OBJ.
    let o = host(&[
        "simplify".as_ref(),
        d("m.obj").as_os_str(),
        s.as_os_str(),
        "--ratio".as_ref(),
        "0.5".as_ref(),
        "--no-measure".as_ref(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let bad = {
        let mut j = json.clone();
        let pa = j["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
            .as_u64()
            .unwrap() as usize;
        j["accessors"][pa]["count"] = json!(1_000_000_000u64);
        [
            ("truncated.glb", bytes[..bytes.len() / 2].to_vec()),
            ("junk.glb", b"glTF\x02\0\0\0junk".to_vec()),
            ("junk.gltf", b"{ not json".to_vec()),
            ("count.glb", glb(&j, &bin)),
        ]
    };
    for (name, b) in &bad {
        std::fs::write(d(name), b).unwrap();
    }
    for (cmd, args) in &runs {
        let with = |input: &str, out: &str| -> std::process::Output {
            let a: Vec<std::ffi::OsString> = args
                .iter()
                .map(|a| match a.to_str() {
                    Some("M") => d(input).into_os_string(),
                    Some("OUT") => d(out).into_os_string(),
                    _ => a.to_os_string(),
                })
                .collect();
            let a: Vec<&std::ffi::OsStr> = a.iter().map(|x| x.as_os_str()).collect();
            host(&a)
        };
        let from_glb = with("m.glb", "c1.obj");
        let from_obj = with("m.obj", "c2.obj");
        assert!(from_glb.status.success(), "{cmd}: {}", text(&from_glb));
        assert!(from_obj.status.success(), "{cmd}: {}", text(&from_obj));
        // Times differ from run to run; everything else is the same.
        let same = |o: &std::process::Output| -> Vec<String> {
            String::from_utf8_lossy(&o.stdout)
                .lines()
                .filter(|l| !l.contains("time"))
                .map(|l| {
                    l.replace(&d("m.glb").display().to_string(), "M")
                        .replace(&d("m.obj").display().to_string(), "M")
                        .replace(&d("c1.obj").display().to_string(), "OUT")
                        .replace(&d("c2.obj").display().to_string(), "OUT")
                })
                .collect()
        };
        assert_eq!(same(&from_glb), same(&from_obj), "{cmd}");
        let out = String::from_utf8_lossy(&from_glb.stdout).to_string();
        assert!(
            out.contains(&triangles.to_string()),
            "{cmd} does not print {triangles}:\n{out}"
        );
        if cmd.starts_with("cluster") {
            assert_eq!(
                std::fs::read(d("c1.obj")).unwrap(),
                std::fs::read(d("c2.obj")).unwrap()
            );
        }
        for (name, _) in &bad {
            let o = with(name, "c3.obj");
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{cmd} {name}: {}", text(&o));
            assert_eq!(err.trim_end().lines().count(), 1, "{cmd} {name}: {err}");
            assert!(err.contains(name) && !err.contains("panick"), "{err}");
        }
    }
}

/// glTF in, OBJ, PLY or STL out: the primitives simplified as for glTF out, the geometry
/// written; the OBJ with each kept vertex's texture coordinates (v flipped: OBJ's v runs up
/// the image) and normals, and one line naming what OBJ cannot hold. `check` finds the OBJ a
/// valid simplification of the GLB.
#[test]
fn simplify_glb_to_obj_ply_stl_writes_the_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n);
    let (json, bin) = document();
    let bytes = glb(&json, &bin);
    std::fs::write(d("m.glb"), &bytes).unwrap();
    let simplify = |out: &str| {
        let o = host(&[
            "simplify".as_ref(),
            d("m.glb").as_os_str(),
            d(out).as_os_str(),
            "--ratio".as_ref(),
            "0.4".as_ref(),
        ]);
        assert!(o.status.success(), "{out}: {}", text(&o));
        let t = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(!t.contains("NOT valid"), "{t}");
        // "... 362 -> N triangles" on the first line.
        let first = t.lines().next().unwrap().to_string();
        let n: usize = first
            .rsplit("-> ")
            .next()
            .and_then(|r| r.split_whitespace().next())
            .and_then(|x| x.parse().ok())
            .unwrap_or_else(|| panic!("{first}"));
        (n, first, String::from_utf8_lossy(&o.stderr).to_string())
    };
    let (n_glb, _, _) = simplify("s.glb");
    let (n_obj, head, err) = simplify("s.obj");
    assert_eq!(n_obj, n_glb);
    assert!(n_obj < 362 && head.contains("362 -> "), "{head}");
    assert!(head.contains("glTF to OBJ"), "{head}");
    // One line on what is not written: the colours, the material's texture, the node transforms.
    let notes: Vec<&str> = err.lines().filter(|l| l.contains("not written")).collect();
    assert_eq!(notes.len(), 1, "{err}");
    assert!(
        notes[0].contains("COLOR_0") && notes[0].contains("node"),
        "{err}"
    );

    // The OBJ, read here line by line: every corner a position, texture coordinate and normal
    // of one input vertex (texture coordinates as (u, 1 - v)).
    let obj = std::fs::read_to_string(d("s.obj")).unwrap();
    let floats = |l: &str| -> Vec<f32> {
        l.split_whitespace()
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect()
    };
    let lines = |key: &str| -> Vec<Vec<f32>> {
        obj.lines()
            .filter(|l| l.split_whitespace().next() == Some(key))
            .map(floats)
            .collect()
    };
    let (vs, vts, vns) = (lines("v"), lines("vt"), lines("vn"));
    let input = read_with_gltf_crate(&bytes);
    let mut corners_with_uv = 0;
    let mut corners_with_normal = 0;
    let mut tris = 0;
    for l in obj.lines().filter(|l| l.starts_with("f ")) {
        tris += 1;
        for c in l.split_whitespace().skip(1) {
            let ix: Vec<Option<usize>> = c
                .split('/')
                .map(|x| x.parse::<usize>().ok().map(|i| i - 1))
                .collect();
            let p = vs[ix[0].unwrap()]
                .iter()
                .map(|x| x.to_bits())
                .collect::<Vec<_>>();
            let uv = ix.get(1).copied().flatten().map(|t| &vts[t]);
            let n = ix.get(2).copied().flatten().map(|t| &vns[t]);
            let found = input.iter().flat_map(|(v, _)| v).any(|v| {
                v.1[..] == p[..]
                    && n.is_none_or(|n| v.2.is_some_and(|vn| vn.map(f32::from_bits)[..] == n[..]))
                    && uv.is_none_or(|uv| {
                        v.3.is_some_and(|t| {
                            f32::from_bits(t[0]) == uv[0]
                                && (1.0 - f32::from_bits(t[1]) - uv[1]).abs() < 1e-6
                        })
                    })
            });
            assert!(found, "corner {c} of {l}: {p:?} {n:?} {uv:?}");
            corners_with_uv += usize::from(uv.is_some());
            corners_with_normal += usize::from(n.is_some());
        }
    }
    assert!(corners_with_normal > corners_with_uv);
    assert_eq!(tris, n_obj);
    assert!(corners_with_uv > 0);
    // `check` reads both, with simplify's counts. (Its verdict is on the primitives side by
    // side in their own coordinates, where this file's overlap; simplify's per-part verdict
    // above is the one that holds.)
    let o = host(&[
        "check".as_ref(),
        d("m.glb").as_os_str(),
        d("s.obj").as_os_str(),
    ]);
    assert_ne!(o.status.code(), Some(2), "{}", text(&o));
    let counts: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter(|l| l.trim_start().starts_with("triangles "))
        .map(|l| l.split_whitespace().last().unwrap().to_string())
        .collect();
    assert_eq!(
        counts,
        ["362".to_string(), n_obj.to_string()],
        "{}",
        text(&o)
    );

    // PLY and STL: the same triangles, positions only, and the line says so.
    for out in ["s.ply", "s.stl"] {
        let (n, head, err) = simplify(out);
        assert_eq!(n, n_glb, "{head}");
        let m = tinydecimate_cli::io::load(d(out)).unwrap();
        assert_eq!(m.triangles.len(), n);
        let notes: Vec<&str> = err.lines().filter(|l| l.contains("not written")).collect();
        assert_eq!(notes.len(), 1, "{err}");
        assert!(
            notes[0].contains("TEXCOORD_0") && notes[0].contains("NORMAL"),
            "{err}"
        );
    }
}

/// A mesh two nodes place (instancing): `simplify` counts its triangles once; `render` prints
/// that count and says how many the scene draws; `check` notes it.
#[test]
fn instanced_mesh_counts_agree_between_simplify_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n);
    let (mut json, bin) = document();
    json["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"mesh": 1, "translation": [20.0, 0.0, 0.0]}));
    json["scenes"][0]["nodes"] = json!([0, 1, 2]);
    std::fs::write(d("m.glb"), glb(&json, &bin)).unwrap();
    let o = host(&[
        "simplify".as_ref(),
        d("m.glb").as_os_str(),
        d("s.glb").as_os_str(),
        "--ratio".as_ref(),
        "0.5".as_ref(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let t = String::from_utf8_lossy(&o.stdout).to_string();
    let head = t.lines().next().unwrap();
    let (tin, tout) = {
        let (a, b) = head
            .rsplit_once(": ")
            .unwrap()
            .1
            .split_once(" -> ")
            .unwrap();
        (
            a.parse::<usize>().unwrap(),
            b.split_whitespace()
                .next()
                .unwrap()
                .parse::<usize>()
                .unwrap(),
        )
    };
    assert_eq!(tin, 362, "{head}");
    // mesh 1 (primitive B) in the result.
    let out = std::fs::read(d("s.glb")).unwrap();
    let b_out = read_with_gltf_crate(&out)[2].1.len() / 3;
    let o = host(&[
        "render".as_ref(),
        d("s.glb").as_os_str(),
        d("c.png").as_os_str(),
        "--compare".as_ref(),
        d("m.glb").as_os_str(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let r = String::from_utf8_lossy(&o.stdout);
    let want = format!(
        "panels: original ({tin} triangles, {} drawn: mesh 1 drawn 2 times) | simplified ({tout} \
         triangles, {} drawn: mesh 1 drawn 2 times)",
        tin + 72,
        tout + b_out
    );
    assert!(r.contains(&want), "{r}\nwanted {want}");
    let o = host(&[
        "render".as_ref(),
        d("m.glb").as_os_str(),
        d("m.png").as_os_str(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let r = String::from_utf8_lossy(&o.stdout);
    assert!(
        r.contains(&format!("{tin} triangles, {} drawn", tin + 72)),
        "{r}"
    );
    // Without instancing the counts are one number.
    let (plain, bin) = document();
    std::fs::write(d("p.glb"), glb(&plain, &bin)).unwrap();
    let o = host(&[
        "render".as_ref(),
        d("p.glb").as_os_str(),
        d("p.png").as_os_str(),
    ]);
    let r = String::from_utf8_lossy(&o.stdout);
    assert!(
        r.contains(": 362 triangles\n") && !r.contains("drawn"),
        "{r}"
    );
    // `check` reads the scene as `simplify` does and says how the scene differs.
    let o = host(&[
        "check".as_ref(),
        d("m.glb").as_os_str(),
        d("s.glb").as_os_str(),
    ]);
    assert_ne!(o.status.code(), Some(2), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!(
            "the scene draws {} triangles: mesh 1 drawn 2 times",
            tin + 72
        )),
        "{err}"
    );
}

/// A file as [`read_with_gltf_crate`] reads it.
type Read = Vec<(Vec<Vertex>, Vec<u32>)>;

/// `simplify INPUT DIR/out.glb --ratio RATIO --json EXTRA...`: the report and the output as
/// the `gltf` crate reads it.
fn simplify_json(
    input: &std::path::Path,
    dir: &std::path::Path,
    extra: &[&str],
    ratio: &str,
) -> (Value, Read) {
    let output = dir.join("out.glb");
    let o = Command::new(env!("CARGO_BIN_EXE_tinydecimate"))
        .arg("simplify")
        .arg(input)
        .arg(&output)
        .args(["--ratio", ratio, "--json"])
        .args(extra)
        .output()
        .unwrap();
    let j: Value = serde_json::from_slice(&o.stdout).unwrap_or_else(|_| {
        panic!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        )
    });
    (j, read_with_gltf_crate(&std::fs::read(&output).unwrap()))
}

/// One mesh of three materials that share edges, as an exporter writes a car's body, window
/// and trim: an `n`x`n` height field cut into a body, a window in its middle and a trim strip,
/// each region a primitive with its own copies of the vertices on its boundary (positions
/// bit-identical), its own texture coordinates and normals.
fn three_materials(n: usize) -> Vec<u8> {
    let region = |x: usize, y: usize| {
        if (n / 4..3 * n / 4).contains(&x) && (n / 4..n / 2).contains(&y) {
            1
        } else if (3 * n / 4..3 * n / 4 + 2).contains(&y) {
            2
        } else {
            0
        }
    };
    let p = |x: usize, y: usize| {
        let (fx, fy) = (x as f32 / n as f32, y as f32 / n as f32);
        [fx, fy, 0.15 * (fx * 5.0).sin() * (fy * 3.0).cos()]
    };
    let mut b = Builder::default();
    let mut primitives = Vec::new();
    for r in 0..3 {
        let (mut pos, mut nrm, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut id = vec![u32::MAX; (n + 1) * (n + 1)];
        let mut vertex = |x: usize, y: usize| {
            let k = y * (n + 1) + x;
            if id[k] == u32::MAX {
                id[k] = (pos.len() / 3) as u32;
                pos.extend_from_slice(&p(x, y));
                nrm.extend_from_slice(&[0.0, 0.0, 1.0]);
                // Each material's own texture space.
                uv.extend_from_slice(&[x as f32 / n as f32 + r as f32, y as f32 / n as f32]);
            }
            id[k]
        };
        for y in 0..n {
            for x in 0..n {
                if region(x, y) != r {
                    continue;
                }
                let (a, b2, c, d) = (
                    vertex(x, y),
                    vertex(x + 1, y),
                    vertex(x + 1, y + 1),
                    vertex(x, y + 1),
                );
                idx.extend_from_slice(&[a, b2, c, a, c, d]);
            }
        }
        let pa = b.floats(&pos, "VEC3", 3);
        let na = b.floats(&nrm, "VEC3", 3);
        let ta = b.floats(&uv, "VEC2", 2);
        let ib: Vec<u8> = idx.iter().flat_map(|&i| i.to_le_bytes()).collect();
        let iv = b.view(&ib, None);
        let ia = b.accessor(iv, 0, 5125, "SCALAR", idx.len());
        primitives.push(json!({
            "attributes": {"POSITION": pa, "NORMAL": na, "TEXCOORD_0": ta},
            "indices": ia, "material": r
        }));
    }
    let materials = json!([{"name": "body"}, {"name": "window"}, {"name": "trim"}]);
    one_mesh_glb(b, primitives, materials)
}

/// The primitives of one mesh are simplified together, their shared boundaries as seams:
/// welded by position, the result has no open edge the input did not have (no gap between
/// materials), every primitive keeps triangles, every written vertex is an input vertex of its
/// own primitive, and the target applies to the mesh as a whole; both engines. With
/// `--per-primitive` each primitive's boundary moves on its own and gaps open (the figure the
/// joined run is judged by can fail).
#[test]
fn primitives_of_one_mesh_simplify_together_without_gaps() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("three.glb");
    std::fs::write(&input, three_materials(24)).unwrap();
    let bytes = std::fs::read(&input).unwrap();
    let inputs = read_with_gltf_crate(&bytes);
    let total: usize = inputs.iter().map(|(_, i)| i.len() / 3).sum();
    let run = |extra: &[&str], ratio: &str| simplify_json(&input, dir.path(), extra, ratio);
    for ratio in ["0.25", "0.1"] {
        for engine in [
            &["--engine", "fast"][..],
            &["--engine", "lean"],
            &["--engine", "exact"],
        ] {
            let (j, out) = run(engine, ratio);
            assert_eq!(j["valid"], true, "{engine:?} {ratio}: {j:#}");
            let gaps = &j["welded_parts"][0];
            assert_eq!(gaps["new_open_edges"], 0, "{engine:?} {ratio}: {j:#}");
            assert_eq!(
                j["parts"].as_array().unwrap().len(),
                1,
                "one run for the mesh"
            );
            let kept: usize = out.iter().map(|(_, i)| i.len() / 3).sum();
            let goal = (total as f32 * ratio.parse::<f32>().unwrap()) as usize;
            assert!(
                kept <= goal + 2,
                "{engine:?} {ratio}: {kept} of {total} for {goal}"
            );
            for (k, ((verts, idx), (inv, _))) in out.iter().zip(&inputs).enumerate() {
                assert!(!idx.is_empty(), "{engine:?} {ratio}: primitive {k} lost");
                let own: HashSet<Vertex> = inv.iter().copied().collect();
                for v in verts {
                    assert!(
                        own.contains(v),
                        "primitive {k}: {v:?} is not one of its vertices"
                    );
                }
            }
        }
        let (j, _) = run(&["--per-primitive"], ratio);
        assert!(
            j["welded_parts"][0]["new_open_edges"].as_u64().unwrap() > 0,
            "per primitive, borders move apart: {j:#}"
        );
    }
}

/// A real model of several materials (tests/fixtures/CesiumMilkTruck.glb: the truck's body,
/// glass and window trim are three primitives of one mesh): at 25 % and 10 %, in the default
/// engine and the exact one, the truck's primitives welded by position have no open edge the
/// input did not have, every primitive keeps triangles, and the output is valid. Per primitive
/// the windows' edges open.
#[test]
fn the_milk_truck_keeps_its_windows_closed() {
    let input = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/CesiumMilkTruck.glb");
    let dir = tempfile::tempdir().unwrap();
    let run = |extra: &[&str], ratio: &str| simplify_json(&input, dir.path(), extra, ratio);
    for ratio in ["0.25", "0.1"] {
        for extra in [&[][..], &["--engine", "exact"]] {
            let what = format!("{extra:?} at {ratio}");
            let (j, out) = run(extra, ratio);
            assert_eq!(j["valid"], true, "{what}: {j:#}");
            let truck = &j["welded_parts"][0];
            assert_eq!(truck["open_edges_in"], 8, "{what}: {j:#}");
            assert_eq!(truck["new_open_edges"], 0, "{what}: {j:#}");
            assert_eq!(out.len(), 4, "{what}");
            for (k, (_, idx)) in out.iter().enumerate() {
                assert!(!idx.is_empty(), "{what}: primitive {k} lost");
            }
        }
        let (j, _) = run(&["--per-primitive"], ratio);
        assert!(
            j["welded_parts"][0]["new_open_edges"].as_u64().unwrap() > 0,
            "{j:#}"
        );
    }
}

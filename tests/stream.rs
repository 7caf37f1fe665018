//! The progressive stream: encode → decode gives back the full mesh exactly (and the positions
//! bit for bit, or within half a quantisation step), every level on the way is the encoder's
//! level, and damaged or truncated streams give typed errors with the last valid level kept.

mod common;
use common::*;
use tinydecimate::progressive::{Split, Storage};
use tinydecimate::stream::{self, Decoder, StreamError, HEADER};
use tinydecimate::{Config, Progressive};

struct Store {
    tris: Vec<Tri>,
    links: Vec<Tri>,
    heads: Vec<u32>,
    splits: Vec<Split<u32>>,
}

impl Store {
    fn new(v: usize, t: usize) -> Self {
        Store {
            tris: vec![[0; 3]; t],
            links: vec![[0; 3]; t],
            heads: vec![0; v],
            splits: vec![Split::EMPTY; v],
        }
    }
    fn storage(&mut self) -> Storage<'_, u32> {
        Storage {
            triangles: &mut self.tris,
            links: &mut self.links,
            heads: &mut self.heads,
            splits: &mut self.splits,
        }
    }
}

/// The simplifier's collapse log for `m` at `ratio`.
fn collapse_log(m: &MeshData, ratio: f32) -> Vec<[u32; 2]> {
    simplify_logged(m, &Config::new().with_ratio(ratio)).0
}

/// Simplifies `m` to `ratio` with a log, builds the progressive mesh and encodes it.
/// Returns the stream, the levels' triangles by level, and the renumbered positions.
fn encoded(m: &MeshData, ratio: f32, quantised: bool) -> (Vec<u8>, Vec<Vec<Tri>>, Vec<[f32; 3]>) {
    encoded_in_chunks(m, ratio, quantised, 256)
}

/// [`encoded`] with chunk payloads of at most `chunk` bytes.
fn encoded_in_chunks(
    m: &MeshData,
    ratio: f32,
    quantised: bool,
    chunk: u16,
) -> (Vec<u8>, Vec<Vec<Tri>>, Vec<[f32; 3]>) {
    encode_log(m, &collapse_log(m, ratio), quantised, chunk)
}

/// The stream of `m` with the collapses of `log`, its levels and renumbered positions.
fn encode_log(
    m: &MeshData,
    log: &[[u32; 2]],
    quantised: bool,
    chunk: u16,
) -> (Vec<u8>, Vec<Vec<Tri>>, Vec<[f32; 3]>) {
    let (v, t) = (m.positions.len(), m.triangles.len());
    let mut st = Store::new(v, t);
    let (mut order, mut scratch) = (vec![0u32; v], vec![0u32; t]);
    let mut pm =
        Progressive::from_log(&m.triangles, v, log, st.storage(), &mut order, &mut scratch)
            .unwrap();
    let mut out = vec![0u8; 64 * t + 4096];
    let e = stream::encode(&mut pm, &m.positions, &order, quantised, chunk, &mut out).unwrap();
    out.truncate(e.bytes);
    pm.set_level(0);
    let mut levels = vec![pm.triangles().to_vec()];
    while pm.refine(1) == 1 {
        levels.push(pm.triangles().to_vec());
    }
    let nv = pm.base_vertices() + pm.levels();
    let positions = order[..nv]
        .iter()
        .map(|&i| m.positions[i as usize])
        .collect();
    (out, levels, positions)
}

/// Decodes `bytes` fed in pieces of `piece` bytes; checks the level after every piece against
/// the encoder's. Returns the decoder's result and level.
fn decode(
    bytes: &[u8],
    piece: usize,
    levels: &[Vec<Tri>],
    v: usize,
    t: usize,
) -> (Result<(), StreamError>, usize, Vec<[f32; 3]>) {
    let mut st = Store::new(v, t);
    let mut pos = vec![[0f32; 3]; v];
    let mut buf = vec![0u8; 512];
    let mut d = Decoder::new(st.storage(), &mut pos, &mut buf);
    let mut r = Ok(());
    for p in bytes.chunks(piece) {
        r = d.push(p);
        let pm = d.mesh();
        if pm.levels() > 0 || pm.base_triangles() == levels[0].len() {
            assert_eq!(
                pm.triangles(),
                &levels[pm.level()][..],
                "level {}",
                pm.level()
            );
        }
        if r.is_err() {
            break;
        }
    }
    if r.is_ok() {
        r = d.finish();
    }
    let level = d.mesh().level();
    let positions = d.positions().to_vec();
    (r, level, positions)
}

#[test]
fn round_trip_is_exact_at_every_level_and_any_chunking() {
    let m = load_obj("cow.obj");
    let (v, t) = (m.positions.len(), m.triangles.len());
    let (bytes, levels, positions) = encoded(&m, 0.1, false);
    for piece in [1, 7, 64, 1000, bytes.len()] {
        let (r, level, pos) = decode(&bytes, piece, &levels, v, t);
        assert_eq!(r, Ok(()), "piece {piece}");
        assert_eq!(level, levels.len() - 1);
        // Positions bit for bit.
        assert_eq!(pos.len(), positions.len());
        for (a, b) in pos.iter().zip(&positions) {
            assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits));
        }
    }
}

/// A chunk smaller than one record: the encoder raises it to `MIN_PAYLOAD`. Found by the
/// `roundtrip` fuzz target (`fuzz/regressions/roundtrip-record-overflows-its-chunk`): a disc
/// of 20 triangles around one centre, simplified to a single triangle, has explicit-mode
/// splits of up to 20 mask bits, and with f32 positions one record outgrew a 16-byte chunk,
/// which the decoder then rightly refused (`BadChunk`).
#[test]
fn records_larger_than_the_asked_chunk_still_fit() {
    let mut positions = vec![[0.0f32; 3]];
    let mut triangles = Vec::new();
    for k in 0..20u32 {
        let a = k as f32 * std::f32::consts::TAU / 20.0;
        positions.push([a.cos(), a.sin(), 0.0]);
        triangles.push([0, 1 + k, 1 + (k + 1) % 20]);
    }
    let disc = MeshData {
        positions,
        triangles,
    };
    let mut meshes = vec![("disc", disc, 0.0)];
    for name in ["cow.obj", "plate_holes.obj"] {
        meshes.push((name, load_obj(name), 0.05));
    }
    for (name, m, ratio) in meshes {
        let (v, t) = (m.positions.len(), m.triangles.len());
        let (bytes, levels, _) = encoded_in_chunks(&m, ratio, false, 16);
        assert_eq!(
            u16::from_le_bytes([bytes[24], bytes[25]]),
            stream::MIN_PAYLOAD,
            "{name}: max payload in the header"
        );
        let (r, level, _) = decode(&bytes, 13, &levels, v, t);
        assert_eq!(r, Ok(()), "{name}");
        assert_eq!(level, levels.len() - 1, "{name}");
    }
}

/// A kept vertex with more than 64 triangles: the two apexes of a double cone over a rim of
/// 68. Found by the `roundtrip` fuzz target
/// (`fuzz/regressions/roundtrip-kept-vertex-over-64-triangles`): the encoder wrote the split
/// (its moved triangles are among the first 64 of the list, so the mask names them) but the
/// decoder refused any list longer than 64 (`BadSplit`).
#[test]
fn kept_vertices_of_high_valence_decode() {
    let n = 68u32;
    let mut positions = vec![[0.0f32, 0.0, 1.0]];
    let mut triangles = Vec::new();
    for k in 0..n {
        let a = k as f32 * std::f32::consts::TAU / n as f32;
        positions.push([a.cos(), a.sin(), 0.0]);
        triangles.push([0, 1 + k, 1 + (k + 1) % n]);
    }
    // The bottom cone after the top one: the triangles a split moves to the rim vertex (its
    // bottom ones) have the largest slots, so they head the apex's list.
    for k in 0..n {
        triangles.push([n + 1, 1 + (k + 1) % n, 1 + k]);
    }
    positions.push([0.0, 0.0, -1.0]);
    let cone = MeshData {
        positions,
        triangles,
    };
    let (v, t) = (cone.positions.len(), cone.triangles.len());
    // Rim vertex 5 onto the top apex (68 triangles before and after), then rim vertex 9.
    let (out, levels, _) = encode_log(&cone, &[[5, 0], [9, 0]], false, 256);
    assert_eq!(levels.len(), 3);
    let (r, level, _) = decode(&out, 5, &levels, v, t);
    assert_eq!(r, Ok(()));
    assert_eq!(level, 2);
}

#[test]
fn quantised_positions_are_within_half_a_step() {
    let plate = load_obj("plate_holes.obj");
    // As is; centred and blown up to ±3e38 (the box's span overflows f32); shrunk to
    // subnormal size (the step is below the f32 grid). The last two were found by the
    // `roundtrip` fuzz target.
    let (mut c, mut r) = ([0f32; 3], 0f32);
    let (lo0, hi0) = bbox(&plate.positions);
    for k in 0..3 {
        c[k] = 0.5 * (lo0[k] + hi0[k]);
        r = r.max(0.5 * (hi0[k] - lo0[k]));
    }
    for scale in [None, Some(3e38f32), Some(1e-40f32)] {
        let mut m = plate.clone();
        if let Some(s) = scale {
            for p in &mut m.positions {
                for k in 0..3 {
                    p[k] = (p[k] - c[k]) / r * s;
                }
            }
        }
        let (v, t) = (m.positions.len(), m.triangles.len());
        let (bytes, levels, positions) = encoded(&m, 0.05, true);
        let (res, _, pos) = decode(&bytes, 333, &levels, v, t);
        assert_eq!(res, Ok(()), "scale {scale:?}");
        let (lo, hi) = bbox(&positions);
        for (a, b) in pos.iter().zip(&positions) {
            for k in 0..3 {
                // Half a step (the span taken in halves), plus rounding: a few ulps of the
                // box's extent, and of the subnormal grid.
                let tolerance = (hi[k] * 0.5 - lo[k] * 0.5) / 65535.0
                    + 4.0 * f32::EPSILON * lo[k].abs().max(hi[k].abs())
                    + 4.0 * f32::from_bits(1);
                assert!(
                    a[k].is_finite() && (a[k] - b[k]).abs() <= tolerance,
                    "scale {scale:?}: {a:?} vs {b:?}"
                );
            }
        }
    }
}

fn bbox(p: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in p {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

#[test]
fn damaged_streams_fail_typed_and_keep_the_last_valid_level() {
    let m = load_obj("cow.obj");
    let (v, t) = (m.positions.len(), m.triangles.len());
    let (bytes, levels, _) = encoded(&m, 0.2, false);
    // Truncation anywhere: a typed error, and the decoder's level is one of the encoder's
    // (checked inside `decode` after every piece).
    for cut in [
        0,
        1,
        HEADER - 1,
        HEADER,
        HEADER + 3,
        bytes.len() / 3,
        bytes.len() - 1,
    ] {
        let (r, _, _) = decode(&bytes[..cut], 97, &levels, v, t);
        assert_eq!(r, Err(StreamError::Truncated), "cut at {cut}");
    }
    // A flipped bit anywhere: detected (checksum, or a header field), never applied.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..300 {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let bit = (seed % (bytes.len() as u64 * 8)) as usize;
        let mut bad = bytes.clone();
        bad[bit / 8] ^= 1 << (bit % 8);
        let (r, _, _) = decode(&bad, 500, &levels, v, t);
        assert!(r.is_err(), "bit {bit} slipped through");
    }
    // Bytes after the end.
    let mut long = bytes.clone();
    long.push(0);
    assert_eq!(
        decode(&long, 4096, &levels, v, t).0,
        Err(StreamError::TrailingData)
    );
    // Wrong magic and version.
    let mut b = bytes.clone();
    b[0] = b'X';
    assert_eq!(
        decode(&b, 4096, &levels, v, t).0,
        Err(StreamError::BadMagic)
    );
    let mut b = bytes.clone();
    b[4] = 9;
    assert_eq!(
        decode(&b, 4096, &levels, v, t).0,
        Err(StreamError::BadVersion(9))
    );
    // Storage too small: refused at the header, nothing decoded.
    let mut st = Store::new(v - 1, t);
    let mut pos = vec![[0f32; 3]; v - 1];
    let mut buf = vec![0u8; 512];
    let mut d = Decoder::new(st.storage(), &mut pos, &mut buf);
    assert!(matches!(
        d.push(&bytes),
        Err(StreamError::Capacity {
            what: "vertices",
            ..
        })
    ));
    assert_eq!(d.mesh().triangles().len(), 0);
}

#[test]
fn split_records_are_small() {
    let m = load_obj("cow.obj");
    let log = collapse_log(&m, 0.02);
    let (v, t) = (m.positions.len(), m.triangles.len());
    let mut st = Store::new(v, t);
    let (mut order, mut scratch) = (vec![0u32; v], vec![0u32; t]);
    let mut pm = Progressive::from_log(
        &m.triangles,
        v,
        &log,
        st.storage(),
        &mut order,
        &mut scratch,
    )
    .unwrap();
    let mut out = vec![0u8; 64 * t];
    for quantised in [false, true] {
        let e = stream::encode(&mut pm, &m.positions, &order, quantised, 1024, &mut out).unwrap();
        let conn = e.split_connectivity_bits as f64 / 8.0 / e.splits as f64;
        let geo = e.split_position_bits as f64 / 8.0 / e.splits as f64;
        println!(
            "cow: {} splits, {:.2} B connectivity + {geo:.1} B position per split, base {} B, total {} B",
            e.splits, conn, e.base_bytes, e.bytes
        );
        assert!(conn <= 3.2, "{conn} B of connectivity per split");
        assert_eq!(geo, if quantised { 6.0 } else { 12.0 });
    }
}

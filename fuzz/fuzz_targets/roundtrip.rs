//! Encode → decode round trips of progressive streams: any generated mesh and configuration
//! (the `simplify` target's generator), simplified with a collapse log, turned into vertex
//! splits, encoded (f32 or quantised positions, any chunk size) and decoded again in pieces
//! of any size. The decoder must accept the encoder's every stream, end at exactly the
//! encoder's full mesh, give the encoder's mesh at every level, and the positions it decodes
//! must be the input's (bit for bit with f32, within half a quantisation step otherwise).
#![no_main]

use tinydecimate_cli::pm::Store;
use libfuzzer_sys::fuzz_target;
use tinydecimate::stream::{self, Decoder};
use tinydecimate::{EdgeCollapse, Progressive, Workspace};

type Ws = Workspace<u32, 1024, 2048>;

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let Ok(case) = tinydecimate_fuzz::Case::generate(&mut u) else {
        return;
    };
    let quantised: bool = u.arbitrary().unwrap_or(false);
    let chunk: u16 = u.int_in_range(16..=600).unwrap_or(64);
    let piece: usize = u.int_in_range(1..=300).unwrap_or(7);
    let (positions, input) = (&case.positions, &case.triangles);
    let (nv, nt) = (positions.len(), input.len());
    if nv > 1024 || nt > 2048 {
        return;
    }

    // Simplify with a collapse log.
    let mut ws: Box<Ws> = Box::new(Workspace::new());
    let mut tris = input.clone();
    let mut log = vec![[0u32; 2]; nv];
    let Ok(s) = ws.start(
        tinydecimate::Positions::Read(positions),
        &mut tris,
        &case.config,
        tinydecimate::Builtin::new(),
        tinydecimate::NoBound,
        EdgeCollapse,
    ) else {
        return;
    };
    let mut s = s.record_into(&mut log);
    while !s.step(u32::MAX) {}
    let n = s.records().len();
    s.finish();
    log.truncate(n);

    // The encoder's progressive mesh.
    let mut store_e = Store::new(nv, nt);
    let (mut order, mut scratch) = (vec![0u32; nv], vec![0u32; nt]);
    let Ok(mut pm) =
        Progressive::from_log(input, nv, &log, store_e.storage(), &mut order, &mut scratch)
    else {
        // The simplifier's own log must always make a progressive mesh, unless a kept vertex
        // ends with more than 64 triangles (a documented limit).
        return;
    };
    let mut out = vec![0u8; stream::HEADER + 64 * (nt + nv) + 4096];
    let e = stream::encode(&mut pm, positions, &order, quantised, chunk, &mut out)
        .expect("the encoder's output buffer is large enough");
    out.truncate(e.bytes);

    // Decode in pieces.
    let mut store_d = Store::new(nv, nt);
    let mut pos = vec![[0f32; 3]; nv];
    let mut buf = vec![
        0u8;
        (usize::from(chunk.max(stream::MIN_PAYLOAD)) + stream::CHUNK_OVERHEAD)
            .max(stream::HEADER)
    ];
    let mut d = Decoder::new(store_d.storage(), &mut pos, &mut buf);
    for p in out.chunks(piece) {
        d.push(p)
            .expect("the decoder accepts what the encoder wrote");
    }
    d.finish().expect("complete");
    let h = d.header().expect("header");
    // Half a step (the span in halves: it may exceed the largest f32), plus the rounding of
    // `min·(1 − f) + max·f`: a few ulps of the box's extent, and of the subnormal grid.
    let tolerance = |k: usize| {
        let (lo, hi) = (h.min[k], h.max[k]);
        (hi * 0.5 - lo * 0.5) / 65_535.0
            + 4.0 * f32::EPSILON * lo.abs().max(hi.abs())
            + 4.0 * f32::from_bits(1)
    };
    for (v, (p, &o)) in d.positions().iter().zip(&order).enumerate() {
        let q = positions[o as usize];
        for k in 0..3 {
            if quantised {
                let err = (p[k] - q[k]).abs();
                assert!(
                    err <= tolerance(k),
                    "vertex {v}: coordinate {k} {} vs {} (tolerance {})",
                    p[k],
                    q[k],
                    tolerance(k)
                );
            } else {
                assert_eq!(p[k].to_bits(), q[k].to_bits(), "vertex {v} coordinate {k}");
            }
        }
    }
    // Every level: the decoder's mesh is the encoder's.
    let dm = d.progressive();
    assert_eq!(dm.levels(), pm.levels());
    assert_eq!(dm.triangles(), pm.triangles(), "full mesh");
    pm.set_level(0);
    dm.set_level(0);
    loop {
        assert_eq!(dm.triangles(), pm.triangles(), "level {}", pm.level());
        let (a, b) = (pm.refine(1), dm.refine(1));
        assert_eq!(a, b);
        if a == 0 {
            break;
        }
    }
});

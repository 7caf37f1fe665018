//! The progressive stream decoder on arbitrary bytes fed in arbitrary pieces: never a panic,
//! and after every piece the mesh is a level whose triangles use only vertices that exist.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tinydecimate::progressive::{Split, Storage};
use tinydecimate::stream::Decoder;

fuzz_target!(|data: &[u8]| {
    let Some((&cut, bytes)) = data.split_first() else {
        return;
    };
    let piece = (cut as usize % 64) + 1;
    let (mut tris, mut links) = ([[0u16; 3]; 256], [[0u16; 3]; 256]);
    let (mut heads, mut splits) = ([0u16; 128], [Split::<u16>::EMPTY; 128]);
    let mut pos = [[0f32; 3]; 128];
    let mut buf = [0u8; 1024];
    let storage = Storage {
        triangles: &mut tris,
        links: &mut links,
        heads: &mut heads,
        splits: &mut splits,
    };
    let mut d = Decoder::new(storage, &mut pos, &mut buf);
    for p in bytes.chunks(piece) {
        let r = d.push(p);
        let m = d.mesh();
        let nv = m.vertices();
        for t in m.triangles() {
            assert!(
                t.iter().all(|&i| (i as usize) < nv),
                "{t:?} past {nv} vertices"
            );
            assert!(
                t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
                "degenerate {t:?}"
            );
        }
        if r.is_err() {
            assert!(d.push(p).is_err(), "a failed decoder must stay failed");
            break;
        }
    }
    let _ = d.finish();
    let m = d.progressive();
    m.set_level(0);
    m.set_level(usize::MAX);
});

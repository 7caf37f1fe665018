//! The command line's progressive-stream file reader (`pm::extent` and `pm::decode_with`, what `pm
//! decode` and `pm levels` run, on complete and partial files): no panic; storage bounded by
//! the file's size whatever its header claims (every vertex it decodes costs at least 6 bytes
//! of the file); a decoded level uses only decoded vertices.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&cut, bytes)) = data.split_first() else {
        return;
    };
    let piece = usize::from(cut) % 97 + 1;
    if let Ok(e) = tinydecimate_cli::pm::extent(bytes) {
        assert!(e.bytes <= bytes.len());
        assert!(
            6 * (e.positions + e.splits) <= bytes.len(),
            "{e:?} from {} bytes",
            bytes.len()
        );
    }
    if let Ok(d) = tinydecimate_cli::pm::decode_with(bytes, piece, None, &[0.1, 0.5]) {
        let n = d.positions.len();
        assert!(6 * n <= bytes.len(), "{n} vertices from {} bytes", bytes.len());
        let levels = d.levels.iter().flat_map(|(_, l)| l);
        for t in d.triangles.iter().chain(levels) {
            assert!(t.iter().all(|&i| (i as usize) < n), "{t:?} past {n} vertices");
        }
    }
});

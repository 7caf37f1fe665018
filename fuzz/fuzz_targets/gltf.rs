//! The command line's glTF reader and writer (`tinydecimate_cli::gltf`): no panic and no allocation beyond the
//! input's size on any bytes (GLB or JSON); what it reads has indices in range and one element
//! per vertex in every attribute; writing it back (triangles unchanged) gives a file it reads
//! again with the same triangles and the same attribute bytes per corner.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(file) = tinydecimate_cli::gltf::parse(data, None) else {
        return;
    };
    for p in &file.primitives {
        let n = p.positions.len();
        assert!(p.triangles.iter().flatten().all(|&i| (i as usize) < n));
        for s in p.attributes.iter().chain(p.targets.iter().flatten()) {
            assert_eq!(s.count(), n, "{}", s.semantic);
        }
    }
    let results: Vec<Vec<[u32; 3]>> = file.primitives.iter().map(|p| p.triangles.clone()).collect();
    let (out, _) = tinydecimate_cli::gltf::write(&file, &results, true, "").expect("writes what it read");
    let again = tinydecimate_cli::gltf::parse(&out, None).expect("reads what it wrote");
    assert_eq!(again.primitives.len(), file.primitives.len());
    for (a, b) in file.primitives.iter().zip(&again.primitives) {
        assert_eq!(a.triangles.len(), b.triangles.len());
        assert_eq!(a.attributes.len(), b.attributes.len());
        for (sa, sb) in a.attributes.iter().zip(&b.attributes) {
            assert_eq!(sa.semantic, sb.semantic);
            for (ta, tb) in a.triangles.iter().zip(&b.triangles) {
                for k in 0..3 {
                    assert_eq!(sa.element(ta[k] as usize), sb.element(tb[k] as usize));
                }
            }
        }
    }
});

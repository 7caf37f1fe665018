//! The library on generated meshes (raw, grids, tori, spheres, cubes, fans; NaN/Inf/huge/
//! subnormal coordinates; out-of-range indices), any configuration, the three workspace types
//! and both index types, with output invariants checked after every successful run and
//! stepping compared with one-shot.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    if let Ok(case) = tinydecimate_fuzz::Case::generate(&mut u) {
        case.check();
    }
});

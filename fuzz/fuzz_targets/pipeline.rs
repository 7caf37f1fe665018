//! The pipeline's fast and lean modes (`tinydecimate::pipeline`) on the generated meshes of
//! the `simplify` target (raw, grids, tori, spheres, cubes, fans; NaN/Inf/huge/subnormal
//! coordinates; out-of-range indices), both link and index types, in both arithmetics (the
//! integer one on the positions `pipeline::quantise` puts on its grid, and with one vertex
//! moved off it): the documented error with the buffer untouched, or an output the shared
//! checker finds valid, the same again on a reused workspace.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    if let Ok(case) = tinydecimate_fuzz::Case::generate(&mut u) {
        case.check_pipeline();
    }
});

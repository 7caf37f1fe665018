//! The envelope bound (`bound::Envelope`) on the generated meshes of the `simplify` target,
//! with the edge collapse and with vertex decimation: a documented error with the buffer
//! untouched, or an output the shared checker finds valid whose sampled distance to the input,
//! both ways, is within the bound.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    if let Ok(case) = tinydecimate_fuzz::Case::generate(&mut u) {
        case.check_envelope();
    }
});

//! host-sim's PLY reader (`io::parse_bytes`): no panic, and what it returns keeps the
//! loader's promises (triangles, indices in range, finite coordinates).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = tinydecimate_cli::io::parse_bytes(data, "ply") {
        tinydecimate_fuzz::check_mesh_data(&m);
    }
});

//! meshfmt result files (firmware -> host): no panic; decode(encode(decode(x))) == decode(x).
#![no_main]

use libfuzzer_sys::fuzz_target;
use meshfmt::file::{decode_result, encode_result};

fuzz_target!(|data: &[u8]| {
    let Ok((h, t)) = decode_result(data) else {
        return;
    };
    assert_eq!(t.len() * h.index_type.triangle_bytes(), h.triangles_len());
    let bytes = encode_result(&h, &t).expect("decoded result re-encodes");
    let (h2, t2) = decode_result(&bytes).expect("re-encoded result decodes");
    assert_eq!(h2.to_bytes(), h.to_bytes());
    assert!(h2.same_outcome(&h));
    assert_eq!(t2, t);
});

//! meshfmt case files (host -> firmware): no panic; decode(encode(decode(x))) == decode(x);
//! the configuration maps onto the library's `Config`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use meshfmt::file::{decode_case, encode_case};

fuzz_target!(|data: &[u8]| {
    let Ok((h, p, t, w)) = decode_case(data) else {
        return;
    };
    assert_eq!(p.len(), h.vertices as usize);
    assert_eq!(t.len(), h.triangles as usize);
    let bytes = encode_case(&h, &p, &t, &w).expect("decoded case re-encodes");
    assert_eq!(bytes.len(), h.file_len());
    let (h2, p2, t2, w2) = decode_case(&bytes).expect("re-encoded case decodes");
    assert_eq!(h2.to_bytes(), h.to_bytes());
    let bits = |p: &[[f32; 3]]| p.iter().map(|q| q.map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&p2), bits(&p));
    assert_eq!(t2, t);
    assert_eq!(w2, w);
    let c = meshfmt::lib::config(&h);
    let _ = c.validate();
    let back = meshfmt::lib::case_header(&c, h.index_type);
    assert_eq!(back.feature_mode, h.feature_mode);
});

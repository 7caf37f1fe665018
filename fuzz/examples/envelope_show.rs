//! Runs the `envelope` target's checks on one input: `cargo run --example envelope_show -- <file>`.
fn main() {
    let path = std::env::args().nth(1).expect("usage: envelope_show <file>");
    let data = std::fs::read(&path).expect("read");
    let mut u = arbitrary::Unstructured::new(&data);
    let case = tinydecimate_fuzz::Case::generate(&mut u).expect("decodes");
    case.check_envelope();
    println!("ok");
}

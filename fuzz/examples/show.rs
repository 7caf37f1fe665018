//! Prints the `simplify` case a fuzz input decodes to, then runs its checks:
//! `cargo run --example show -- <file>`.
fn main() {
    let path = std::env::args().nth(1).expect("usage: show <file>");
    let data = std::fs::read(&path).expect("read");
    let mut u = arbitrary::Unstructured::new(&data);
    let case = tinydecimate_fuzz::Case::generate(&mut u).expect("decodes");
    println!("{case:?}");
    case.check();
    println!("ok");
}

//! `tinydecimate embed`: a mesh file as Rust source (or a binary blob) for firmware, run as the
//! built binary. The firmware example's mesh (examples/cortex-m4f/src/cow.rs) is its output.

use std::path::{Path, PathBuf};

mod common;
use common::{bin, run, text};

use tinydecimate_cli::io::load;

/// The example's mesh, compiled here as the firmware compiles it: its statics are what rustc
/// made of the literals.
mod cow {
    include!("../../examples/cortex-m4f/src/cow.rs");
}

/// The example's input and output, relative to the repository's root: the command in the
/// file's header and in examples/cortex-m4f/README.md.
const COW_OBJ: &str = "tests/fixtures/cow.obj";
const COW_RS: &str = "examples/cortex-m4f/src/cow.rs";

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `tinydecimate embed ARGS` and asserts it failed with exit code 2 and one line on stderr,
/// which it returns.
fn fails(args: &[&str]) -> String {
    let o = run(&[&["embed"], args].concat());
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: not one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    err
}

/// The numbers of `static NAME` in generated source, one row per line, as written.
fn rows<'a>(src: &'a str, name: &str) -> Vec<Vec<&'a str>> {
    let start = src
        .lines()
        .position(|l| l.starts_with(&format!("pub static {name}:")))
        .unwrap_or_else(|| panic!("no static {name}"));
    src.lines()
        .skip(start + 1)
        .take_while(|l| *l != "];")
        .map(|l| {
            let l = l
                .trim()
                .strip_prefix('[')
                .unwrap()
                .strip_suffix("],")
                .unwrap();
            l.split(", ").collect()
        })
        .collect()
}

/// The example's generated file is up to date: the command in its header, run from a copy of
/// the repository's layout, writes the same bytes.
#[test]
fn example_mesh_is_what_the_documented_command_writes() {
    let committed = std::fs::read(repo().join(COW_RS)).unwrap();
    let command = format!("//   tinydecimate embed {COW_OBJ} {COW_RS}\n");
    assert!(
        text(&committed).contains(&command),
        "the header names the command"
    );
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(d.path().join("tests/fixtures")).unwrap();
    std::fs::create_dir_all(d.path().join("examples/cortex-m4f/src")).unwrap();
    std::fs::copy(repo().join(COW_OBJ), d.path().join(COW_OBJ)).unwrap();
    let o = bin()
        .current_dir(d.path())
        .args(["embed", COW_OBJ, COW_RS])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let fresh = std::fs::read(d.path().join(COW_RS)).unwrap();
    assert!(
        fresh == committed,
        "{COW_RS} is stale: run `cargo run -p tinydecimate-cli --release -- embed {COW_OBJ} {COW_RS}`"
    );
}

/// The compiled statics of the example's mesh are the OBJ file's, bit for bit, with u16
/// indices (2 903 vertices fit).
#[test]
fn example_mesh_compiles_to_the_files_bits() {
    let m = load(repo().join(COW_OBJ)).unwrap();
    assert_eq!(cow::VERTICES, m.positions.len());
    assert_eq!(cow::TRIANGLES_COUNT, m.triangles.len());
    for (i, (a, b)) in cow::POSITIONS.iter().zip(&m.positions).enumerate() {
        assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits), "vertex {i}");
    }
    let tris: &[[u16; 3]] = &cow::TRIANGLES;
    for (i, (a, b)) in tris.iter().zip(&m.triangles).enumerate() {
        assert_eq!(a.map(u32::from), *b, "triangle {i}");
    }
}

/// Literals as values (what rustc makes of them) and as the text they were written with.
macro_rules! literals {
    ($($x:literal),* $(,)?) => {
        ([$($x),*], [$(stringify!($x)),*])
    };
}

/// Hard values (negative zero, the smallest and largest subnormals, the smallest normal, the
/// largest finite, one ulp above 1, 2^24, values with no short decimal) go through an OBJ file
/// and `embed`: the file holds literals that rustc reads back as the same bits, and so does
/// the blob.
#[test]
fn every_coordinate_round_trips_bit_for_bit() {
    let bits: [u32; 15] = [
        0x8000_0000, // -0.0
        0x0000_0000,
        0x0000_0001,
        0x007f_ffff,
        0x0080_0000,
        0x7f7f_ffff,
        0xff7f_ffff,
        0x3dcc_cccd, // 0.1
        0x3f80_0001,
        0x4b80_0000,
        0x33d6_bf95, // 1e-7
        0x3eaa_aaab, // 1/3
        0xbb23_d70a,
        0x5015_02f9, // 1e10
        0x8000_0001, // the smallest negative subnormal
    ];
    let (compiled, printed): ([f32; 15], [&str; 15]) = literals!(
        -0.0,
        0.0,
        1e-45,
        1.1754942e-38,
        1.1754944e-38,
        3.4028235e38,
        -3.4028235e38,
        0.1,
        1.0000001,
        16777216.0,
        1e-7,
        0.33333334,
        -0.0025,
        10000000000.0,
        -1e-45,
    );
    for (c, b) in compiled.iter().zip(bits) {
        assert_eq!(
            c.to_bits(),
            b,
            "rustc reads the literal {c:?} as these bits"
        );
    }
    // Five vertices of three coordinates each, every one used, written with nine significant
    // digits (enough for any f32), so the reader gets the intended bits.
    let vals: Vec<f32> = bits.iter().map(|&b| f32::from_bits(b)).collect();
    let mut obj = String::new();
    for v in vals.chunks(3) {
        obj += &format!("v {:.8e} {:.8e} {:.8e}\n", v[0], v[1], v[2]);
    }
    obj += "f 1 2 3\nf 3 4 5\nf 5 1 2\n";
    let d = tempfile::tempdir().unwrap();
    let input = d.path().join("hard.obj");
    std::fs::write(&input, obj).unwrap();
    let m = load(&input).unwrap();
    let loaded: Vec<u32> = m.positions.iter().flatten().map(|c| c.to_bits()).collect();
    assert_eq!(loaded, bits, "the OBJ reader's values");

    let out = d.path().join("hard.rs");
    let o = run(&["embed", s(&input), s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let src = std::fs::read_to_string(&out).unwrap();
    let words: Vec<&str> = rows(&src, "POSITIONS").into_iter().flatten().collect();
    // The file holds exactly the literals rustc was shown above.
    assert_eq!(words, printed);
    for (w, b) in words.iter().zip(bits) {
        assert_eq!(w.parse::<f32>().unwrap().to_bits(), b, "{w}");
    }
    assert!(src.contains("pub static TRIANGLES: [[u16; 3]; TRIANGLES_COUNT] = ["));
    assert!(src.contains("pub const VERTICES: usize = 5;"));
    assert!(src.contains("pub const TRIANGLES_COUNT: usize = 3;"));
    let tris = rows(&src, "TRIANGLES");
    assert_eq!(tris, [["0", "1", "2"], ["2", "3", "4"], ["4", "0", "1"]]);
    let header = src.lines().next().unwrap();
    assert!(
        header.starts_with("// ") && header.contains("hard.obj"),
        "{header}"
    );
    assert!(src.contains(&format!(
        "//   tinydecimate embed {} {}\n",
        s(&input),
        s(&out)
    )));

    // The blob: header, positions, indices, little-endian.
    let blob = d.path().join("hard.bin");
    let o = run(&["embed", s(&input), s(&blob), "--blob", "--index", "u32"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let b = std::fs::read(&blob).unwrap();
    let word = |i: usize| u32::from_le_bytes(b[4 * i..4 * i + 4].try_into().unwrap());
    assert_eq!(&b[..4], b"TDM1");
    assert_eq!([word(1), word(2), word(3)], [5, 3, 4]);
    assert_eq!(b.len(), 16 + 12 * 5 + 3 * 3 * 4);
    let positions: Vec<u32> = (4..4 + 15).map(word).collect();
    assert_eq!(positions, bits);
    let indices: Vec<u32> = (19..19 + 9).map(word).collect();
    assert_eq!(indices, [0, 1, 2, 2, 3, 4, 4, 0, 1]);
}

/// An OBJ with `n` vertices on a line and one triangle over the first three.
fn many_vertices(dir: &Path, n: usize) -> PathBuf {
    let mut obj = String::with_capacity(n * 16);
    for i in 0..n {
        obj += &format!("v {i} {} 0\n", i % 7);
    }
    obj += "f 1 2 3\n";
    let p = dir.join(format!("v{n}.obj"));
    std::fs::write(&p, obj).unwrap();
    p
}

/// u16 indices hold 65 535 vertices (the library reserves u16::MAX); one more needs u32,
/// which `auto` picks and `--index u16` refuses with one line and exit code 2.
#[test]
fn index_type_follows_the_vertex_count() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("m.rs");
    let fits = many_vertices(d.path(), 65_535);
    let o = run(&["embed", s(&fits), s(&out), "--index", "u16"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let src = std::fs::read_to_string(&out).unwrap();
    assert!(src.contains("[[u16; 3]; TRIANGLES_COUNT]"));
    assert!(src.contains("//   tinydecimate embed") && src.contains(" --index u16\n"));

    let over = many_vertices(d.path(), 65_536);
    let o = run(&["embed", s(&over), s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let src = std::fs::read_to_string(&out).unwrap();
    assert!(src.contains("[[u32; 3]; TRIANGLES_COUNT]"));
    assert!(src.contains("pub const VERTICES: usize = 65536;"));

    std::fs::remove_file(&out).unwrap();
    let err = fails(&[s(&over), s(&out), "--index", "u16"]);
    assert!(
        err.contains("65536 vertices do not fit u16") && err.contains("--index u32"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
}

/// A NaN position is an error, whether a triangle uses the vertex (the loader refuses it) or
/// not (a literal cannot hold it).
#[test]
fn nan_positions_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("m.rs");
    let unused = d.path().join("unused.obj");
    std::fs::write(&unused, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 NaN 0\nf 1 2 3\n").unwrap();
    let err = fails(&[s(&unused), s(&out)]);
    assert!(err.contains("vertex 4") && err.contains("NaN"), "{err}");
    let used = d.path().join("used.obj");
    std::fs::write(&used, "v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n").unwrap();
    let err = fails(&[s(&used), s(&out)]);
    assert!(
        err.contains("line 3") && err.contains("non-finite"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
    fails(&[s(&d.path().join("missing.obj")), s(&out)]);
}

//! Problems users reported with the `tinydecimate` command line, one test (or more) each: the
//! built binary on small generated files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::{bin, run, text};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn write(dir: &Path, name: &str, body: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    p
}

/// A bumpy n x n grid of triangles as OBJ text.
fn grid_obj(n: usize) -> String {
    let mut s = String::new();
    for y in 0..=n {
        for x in 0..=n {
            let (fx, fy) = (x as f32 / n as f32, y as f32 / n as f32);
            let z = 0.08 * (fx * 7.0).sin() * (fy * 5.0).cos();
            s += &format!("v {fx} {fy} {z}\n");
        }
    }
    let v = |x: usize, y: usize| 1 + y * (n + 1) + x;
    for y in 0..n {
        for x in 0..n {
            let (a, b, c, d) = (v(x, y), v(x + 1, y), v(x + 1, y + 1), v(x, y + 1));
            s += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    s
}

/// Every subcommand's `--help`, nested ones included.
fn all_help() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let cmds: &[&[&str]] = &[
        &[],
        &["simplify"],
        &["cluster"],
        &["metro"],
        &["check"],
        &["render"],
        &["pm"],
        &["pm", "encode"],
        &["pm", "decode"],
        &["pm", "levels"],
        &["embed"],
    ];
    for c in cmds {
        let mut a = c.to_vec();
        a.push("--help");
        let o = run(&a);
        assert_eq!(o.status.code(), Some(0), "{a:?}: {}", text(&o.stderr));
        out.push((c.join(" "), text(&o.stdout)));
    }
    out
}

/// Whether `t` contains `word` followed by a space and a digit (case-insensitive).
fn labelled(t: &str, word: &str) -> Option<String> {
    let low = t.to_lowercase();
    low.match_indices(word).find_map(|(i, _)| {
        let rest = &low[i + word.len()..];
        rest.chars()
            .next()
            .filter(char::is_ascii_digit)
            .map(|_| low[i..(i + word.len() + 3).min(low.len())].to_string())
    })
}

/// Internal labels (issue numbers, the papers' seed numbers) are not in what users read: help
/// texts, printed output (its strings live in cli/src) or the command line's doc comments.
#[test]
fn no_internal_labels_in_help_or_sources() {
    for (cmd, help) in all_help() {
        for w in ["issue ", "seed "] {
            assert!(
                labelled(&help, w).is_none(),
                "tinydecimate {cmd} --help: {help}"
            );
        }
    }
    let mut dirs = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("src")];
    let mut files = Vec::new();
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else {
                files.push(p);
            }
        }
    }
    assert!(files.len() > 20, "{files:?}");
    for p in files {
        let body = std::fs::read_to_string(&p).unwrap();
        for (no, line) in body.lines().enumerate() {
            for w in ["issue ", "seed 0"] {
                assert!(
                    labelled(line, w).is_none(),
                    "{}:{}: {line}",
                    p.display(),
                    no + 1
                );
            }
        }
    }
}

/// `simplify --help`, one flag's paragraph (from its line to the next flag's).
fn flag_help(help: &str, flag: &str) -> String {
    let start = help
        .find(&format!("      {flag}"))
        .unwrap_or_else(|| panic!("{flag} not in {help}"));
    let rest = &help[start + flag.len() + 6..];
    let end = rest.find("\n      -").unwrap_or(rest.len());
    rest[..end].to_string()
}

/// `--max-error` says what is guaranteed (the distance at the control points), not a
/// "guaranteed error bound" of the whole surface.
#[test]
fn max_error_help_says_what_is_guaranteed() {
    let help = text(&run(&["simplify", "--help"]).stdout);
    let h = flag_help(&help, "--max-error");
    assert!(!h.to_lowercase().contains("guaranteed error bound"), "{h}");
    assert!(h.contains("control point"), "{h}");
    assert!(h.contains("centroid") && h.contains("feature edge"), "{h}");
    assert!(h.contains("not bounded") && h.contains("Hausdorff"), "{h}");
}

/// `--help` says what each operator, cost, schedule, quadric and placement is for, and which
/// ones are there for comparison with a paper.
#[test]
fn help_says_what_each_choice_is_for() {
    let help = text(&run(&["simplify", "--help"]).stdout);
    let op = flag_help(&help, "--operator");
    assert!(
        op.contains("edge:") && op.contains("the one to use"),
        "{op}"
    );
    assert!(
        op.contains("triangle:") && op.contains("For comparison") && op.contains("twice as long"),
        "{op}"
    );
    let sc = flag_help(&help, "--schedule");
    assert!(
        sc.contains("greedy:") && sc.contains("the one to use"),
        "{sc}"
    );
    assert!(
        sc.contains("passes:") && sc.contains("For comparison"),
        "{sc}"
    );
    let co = flag_help(&help, "--cost");
    assert!(
        co.contains("quadric:") && co.contains("lowest geometric error"),
        "{co}"
    );
    assert!(
        co.contains("normal:") && co.contains("for comparison"),
        "{co}"
    );
    let q = flag_help(&help, "--quadric");
    assert!(
        q.contains("RAM is tight") && q.contains("40 B per vertex"),
        "{q}"
    );
    let p = flag_help(&help, "--placement");
    assert!(p.contains("--placement optimal"), "{p}");
}

/// `simplify a.stl a.stl` (or any other spelling of the same file) refuses to overwrite its
/// input unless `--force`, and leaves the file as it was.
#[test]
fn simplify_refuses_to_overwrite_its_input() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "a.obj", grid_obj(8));
    let before = std::fs::read(&input).unwrap();
    std::fs::create_dir(d.path().join("sub")).unwrap();
    let other = d.path().join("sub/../a.obj");
    for out in [input.clone(), other] {
        let o = run(&[
            "simplify",
            s(&input),
            s(&out),
            "--ratio",
            "0.5",
            "--no-measure",
        ]);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains("is the input") && e.contains("--force"), "{e}");
        assert_eq!(std::fs::read(&input).unwrap(), before, "input untouched");
    }
    let o = run(&[
        "simplify",
        s(&input),
        s(&input),
        "--ratio",
        "0.5",
        "--no-measure",
        "--force",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_ne!(
        std::fs::read(&input).unwrap(),
        before,
        "overwritten with --force"
    );
    // A new output next to it is fine.
    let o = run(&[
        "simplify",
        s(&input),
        s(&d.path().join("b.obj")),
        "--ratio",
        "0.5",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

/// A NaN in a vertex no face uses is accepted, as the library accepts it (it only checks the
/// vertices its triangles use); a NaN in a used vertex is refused with its line.
#[test]
fn nan_in_an_unused_vertex_is_accepted() {
    let d = tempfile::tempdir().unwrap();
    let body = format!("v nan 0 inf\n{}", grid_obj(8)).replace("f ", "f_");
    // Shift the faces' indices by one for the extra first vertex.
    let mut fixed = String::new();
    for l in body.lines() {
        if let Some(rest) = l.strip_prefix("f_") {
            let idx: Vec<String> = rest
                .split_whitespace()
                .map(|i| (i.parse::<u32>().unwrap() + 1).to_string())
                .collect();
            fixed += &format!("f {}\n", idx.join(" "));
        } else {
            fixed += &format!("{l}\n");
        }
    }
    let input = write(d.path(), "nan.obj", &fixed);
    for extra in [&[][..], &["--keep-numbering"][..]] {
        let out = d.path().join("out.obj");
        let mut a = vec!["simplify", s(&input), s(&out), "--ratio", "0.5"];
        a.extend_from_slice(extra);
        let o = run(&a);
        let so = text(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{so}{}", text(&o.stderr));
        assert!(so.contains("=> VALID"), "{so}");
        let o = run(&["check", s(&input), s(&out)]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stdout));
    }
    let o = run(&["check", s(&input), s(&input)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    // Used by a face: refused, with the line.
    let used = write(d.path(), "used.obj", format!("{fixed}f 1 2 3\n"));
    let o = run(&[
        "simplify",
        s(&used),
        s(&d.path().join("x.obj")),
        "--ratio",
        "0.5",
    ]);
    let e = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("line 1") && e.contains("non-finite"), "{e}");
}

/// Runs host-sim with its virtual memory limited to `kib` KiB (`ulimit -v`): a reader that
/// reserves storage for what a file merely claims fails to allocate and aborts.
fn run_limited(kib: u64, args: &[&str]) -> Output {
    let mut a = vec![
        "-c".to_string(),
        format!("ulimit -v {kib}; exec \"$0\" \"$@\""),
        env!("CARGO_BIN_EXE_tinydecimate").to_string(),
    ];
    a.extend(args.iter().map(|s| s.to_string()));
    Command::new("sh").args(&a).output().unwrap()
}

/// Enough for host-sim to decode or read a small file (it needs about 100 MB of address
/// space: a 12 MB static workspace, thread stacks), far below what the crafted files claim.
const LIMIT_KIB: u64 = 400_000;

/// A stream header (56 bytes, checksum right) claiming `v` vertices and `t` triangles.
fn stream_header(v: u32, base_v: u32, base_t: u32, t: u32) -> Vec<u8> {
    let mut h = vec![0u8; 56];
    h[..4].copy_from_slice(b"TDPM");
    h[4] = 1; // version
    h[5] = 4; // index width
    h[8..12].copy_from_slice(&v.to_le_bytes());
    h[12..16].copy_from_slice(&base_v.to_le_bytes());
    h[16..20].copy_from_slice(&base_t.to_le_bytes());
    h[20..24].copy_from_slice(&t.to_le_bytes());
    h[24..26].copy_from_slice(&256u16.to_le_bytes());
    for k in 0..3 {
        h[40 + 4 * k..44 + 4 * k].copy_from_slice(&1f32.to_le_bytes());
    }
    let c = tinydecimate::stream::crc32(&h[..52]);
    h[52..].copy_from_slice(&c.to_le_bytes());
    h
}

/// No reader allocates in proportion to a count a file merely claims: `pm decode` checks a
/// stream's header (magic, version, checksum) before sizing anything and sizes storage from
/// what the file holds; PLY element counts and binary STL triangle counts are held against the
/// file's size. Each crafted file is read under a memory limit far below its claims, and is
/// refused with a message saying what is wrong.
#[test]
fn no_allocation_from_claimed_counts() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out.obj");
    // 64 bytes of junk whose "counts" look plausible: not a stream.
    let mut junk = vec![b'J'; 64];
    junk[8..12].copy_from_slice(&50_000_000u32.to_le_bytes());
    junk[20..24].copy_from_slice(&100_000_000u32.to_le_bytes());
    let junk = write(d.path(), "JUNK", &junk);
    let obj = write(d.path(), "a.obj", grid_obj(4));
    for f in [&junk, &obj] {
        let o = run_limited(LIMIT_KIB, &["pm", "decode", s(f), s(&out)]);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains("not a progressive stream"), "{e}");
        assert!(!e.contains("claims"), "{e}");
    }
    // A well-formed header (checksum right) claiming 50 million vertices, then the start of
    // a chunk of 60 000 positions.
    let mut h = stream_header(50_000_000, 1_000_000, 2_000_000, 100_000_000);
    h.extend_from_slice(&[200, 0, 1, 0x60, 0xea, 0, 0, 0]);
    let big = write(d.path(), "big.tdpm", &h);
    for cmd in ["decode", "levels"] {
        let mut a = vec!["pm", cmd, s(&big)];
        if cmd == "decode" {
            a.push(s(&out));
        }
        let o = run_limited(LIMIT_KIB, &a);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "pm {cmd}: {e}");
        assert!(e.contains("before its base mesh"), "pm {cmd}: {e}");
    }
    // Mesh readers: a PLY vertex count and a binary STL triangle count past the file's end.
    let ply = write(
        d.path(),
        "big.ply",
        [
            &b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n\
               property float y\nproperty float z\nelement face 1\nproperty list uchar int \
               vertex_indices\nend_header\n"[..],
            &[0u8; 64][..],
        ]
        .concat(),
    );
    let mut stl = vec![0u8; 80];
    stl.extend_from_slice(&100_000_000u32.to_le_bytes());
    stl.extend_from_slice(&[0u8; 150]);
    let stl = write(d.path(), "big.stl", &stl);
    for f in [&ply, &stl] {
        let o = run_limited(LIMIT_KIB, &["check", s(f), s(f)]);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(e.contains("truncated file"), "{e}");
    }
    // A face list whose length (binary or ascii) is far past the file's end.
    let mut bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\nproperty list uint int \
        vertex_indices\nend_header\n"
        .to_vec();
    for c in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        bin.extend_from_slice(&c.to_le_bytes());
    }
    bin.extend_from_slice(&0xffff_fff0u32.to_le_bytes());
    bin.extend_from_slice(&[0u8; 12]);
    let ascii = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
        property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n\
        0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n";
    for (name, body) in [("list.ply", bin), ("list_a.ply", ascii.as_bytes().to_vec())] {
        let f = write(d.path(), name, body);
        let o = run_limited(LIMIT_KIB, &["check", s(&f), s(&f)]);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {e}");
        assert!(e.contains("PLY") && !e.contains("memory"), "{name}: {e}");
    }
    // And a real stream still decodes under the same limit.
    let mesh = write(d.path(), "g.obj", grid_obj(10));
    let tdpm = d.path().join("g.tdpm");
    let o = run(&["pm", "encode", s(&mesh), s(&tdpm)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = run_limited(LIMIT_KIB, &["pm", "decode", s(&tdpm), s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

/// A progressive file that has only partly arrived decodes to its finest complete level:
/// written, exit 0, and a line saying it is partial and which level it is.
#[test]
fn partial_stream_decodes_its_finest_complete_level() {
    let d = tempfile::tempdir().unwrap();
    let mesh = write(d.path(), "g.obj", grid_obj(16));
    let tdpm = d.path().join("g.tdpm");
    let o = run(&["pm", "encode", s(&mesh), s(&tdpm), "--chunk", "64"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let full = std::fs::read(&tdpm).unwrap();
    let out = d.path().join("out.obj");
    let o = run(&["pm", "decode", s(&tdpm), s(&out)]);
    let so = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{so}{}", text(&o.stderr));
    assert!(!so.contains("PARTIAL"), "{so}");
    let faces = |p: &Path| {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .filter(|l| l.starts_with("f "))
            .count()
    };
    assert_eq!(faces(&out), 512);
    let mut last = 0;
    for cut in [full.len() * 2 / 3, full.len() - 1] {
        let part = write(d.path(), "part.tdpm", &full[..cut]);
        let o = run(&["pm", "decode", s(&part), s(&out)]);
        let so = text(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{so}{}", text(&o.stderr));
        let line = so.lines().find(|l| l.starts_with("PARTIAL")).expect(&so);
        assert!(
            line.contains("vertex splits") && line.contains("of 512 triangles"),
            "{line}"
        );
        let n = faces(&out);
        assert!(n > last && n < 512, "{n} triangles from {cut} bytes");
        assert!(line.contains(&format!("({n} of 512 triangles")), "{line}");
        last = n;
        // The level written is a valid mesh; `pm levels` measures against it.
        let o = run(&["check", s(&out), s(&out)]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stdout));
        let o = run(&["pm", "levels", s(&part)]);
        let so = text(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{so}{}", text(&o.stderr));
        assert!(so.starts_with("PARTIAL"), "{so}");
    }
    // Cut inside the base mesh: nothing to show, and it says so.
    let part = write(d.path(), "base.tdpm", &full[..70]);
    let o = run(&["pm", "decode", s(&part), s(&out)]);
    let e = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("before its base mesh"), "{e}");
}

/// `pm levels` shows a progress bar on a terminal (as `simplify` does), and none on a pipe.
/// The terminal is `script`'s pseudo-terminal; the bar's one-second delay is set to 0.
#[test]
fn pm_levels_shows_progress_on_a_terminal() {
    let d = tempfile::tempdir().unwrap();
    let mesh = write(d.path(), "g.obj", grid_obj(20));
    let tdpm = d.path().join("g.tdpm");
    let o = run(&["pm", "encode", s(&mesh), s(&tdpm)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = bin()
        .args(["pm", "levels", s(&tdpm)])
        .env("TINYDECIMATE_PROGRESS_AFTER_MS", "0")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    assert!(!text(&o.stderr).contains("levels measured"), "a pipe");
    let cmd = format!(
        "{} pm levels {}",
        env!("CARGO_BIN_EXE_tinydecimate"),
        s(&tdpm)
    );
    let Ok(o) = Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .env("TINYDECIMATE_PROGRESS_AFTER_MS", "0")
        .output()
    else {
        eprintln!("no `script` (util-linux): the terminal half is not run");
        return;
    };
    let all = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{all}");
    assert!(all.contains("levels measured"), "{all}");
    assert!(all.contains("| level (splits) |"), "{all}");
}

/// The validity block of a `simplify` run (after its "check (" line) or of `check` (after
/// its "validity (" line), up to the verdict.
fn validity_block(out: &str, after: &str) -> String {
    let start = out
        .find(after)
        .unwrap_or_else(|| panic!("{after} not in {out}"));
    let rest = &out[start..];
    let rest = &rest[rest.find('\n').unwrap() + 1..];
    let end = rest.find("=> ").expect(rest);
    let block = &rest[..end + rest[end..].find('\n').unwrap_or(rest.len() - end)];
    // The renumbering note, if any, sits before the block in both.
    block
        .lines()
        .filter(|l| !l.starts_with("note:"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// One checker, one verdict: with optimal placement `simplify` keeps the input's numbering,
/// `check --placement optimal` matches vertices by index (moved ones allowed), and both print
/// the same check for the same file; without the flag `check` says why the moved vertices
/// fail; a file in another numbering is refused rather than matched by position. With subset
/// placement (compact output, matched back by position) the two print the same too.
#[test]
fn simplify_and_check_give_one_verdict() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "g.obj", grid_obj(24));
    let out = d.path().join("o.obj");
    let o = run(&[
        "simplify",
        s(&input),
        s(&out),
        "--ratio",
        "0.1",
        "--quadric",
        "stored",
        "--placement",
        "optimal",
    ]);
    let so = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{so}{}", text(&o.stderr));
    assert!(so.contains("=> VALID"), "{so}");
    assert!(so.contains("input numbering kept"), "{so}");
    let mine = validity_block(&so, "check (");
    let o = run(&["check", s(&input), s(&out), "--placement", "optimal"]);
    let co = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{co}");
    assert_eq!(mine, validity_block(&co, "validity ("));
    assert!(co.contains("new boundary vertices    0") && co.contains("new pinched vertices     0"));
    // Without the flag the moved vertices fail, and the note says what to do.
    let o = run(&["check", s(&input), s(&out)]);
    let co = text(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{co}");
    assert!(co.contains("--placement optimal"), "{co}");
    // STL has no numbering: refused with optimal placement.
    let o = run(&[
        "simplify",
        s(&input),
        s(&d.path().join("o.stl")),
        "--ratio",
        "0.1",
        "--quadric",
        "stored",
        "--placement",
        "optimal",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("STL has no vertex numbering"));
    // A compact file (another numbering) cannot be matched by index: refused.
    let small = d.path().join("small.obj");
    let o = run(&["simplify", s(&input), s(&small), "--ratio", "0.1"]);
    let so = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{so}");
    let o = run(&["check", s(&input), s(&small), "--placement", "optimal"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("by index"), "{}", text(&o.stderr));
    // Subset placement, compact output matched back by position: the same block.
    let o = run(&["check", s(&input), s(&small)]);
    let co = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{co}");
    assert_eq!(
        validity_block(&so, "check ("),
        validity_block(&co, "validity (")
    );
}

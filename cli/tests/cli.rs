//! The `host-sim` command line as a new user meets it: each test runs the
//! built binary on small generated files.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Stdio;

mod common;
use common::{bin, run, text};

/// A bumpy n x n grid of quads (with texture coordinates and normals) plus one vertex no face
/// uses, as OBJ text; `tris` writes triangles instead of quads.
fn bumpy_obj(n: usize, quads: bool) -> String {
    let mut s = String::from("# bumpy grid\nv 9 9 9\n");
    for y in 0..=n {
        for x in 0..=n {
            let (fx, fy) = (x as f32 / n as f32, y as f32 / n as f32);
            let z = 0.08 * (fx * 7.0).sin() * (fy * 5.0).cos();
            s += &format!("v {fx} {fy} {z}\n");
        }
    }
    s += "vt 0 0\nvn 0 0 1\n";
    let v = |x: usize, y: usize| 2 + y * (n + 1) + x; // 1-based, after the stray vertex
    for y in 0..n {
        for x in 0..n {
            let (a, b, c, d) = (v(x, y), v(x + 1, y), v(x + 1, y + 1), v(x, y + 1));
            if quads {
                s += &format!("f {a}/1/1 {b}/1/1 {c}/1/1 {d}/1/1\n");
            } else {
                s += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
            }
        }
    }
    s
}

fn write(dir: &Path, name: &str, body: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn v_lines(p: &Path) -> usize {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("v "))
        .count()
}

/// Item 1: a duplicate triangle the library drops does not make a valid result INVALID; the
/// check says it compares with the cleaned input.
#[test]
fn duplicate_triangle_in_the_input_is_not_invalid() {
    let d = tempfile::tempdir().unwrap();
    let mut body = bumpy_obj(12, false);
    body += "f 2 3 16\nf 2 3 16\n"; // the first triangle, twice more
    let input = write(d.path(), "dup.obj", &body);
    let out = d.path().join("out.obj");
    let o = run(&["simplify", s(&input), s(&out), "--ratio", "0.2"]);
    let so = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{so}\n{}", text(&o.stderr));
    assert!(so.contains("duplicates dropped     2"), "{so}");
    assert!(
        so.contains("check (output vs the cleaned input") && so.contains("2 duplicate"),
        "{so}"
    );
    assert!(so.contains("=> VALID"), "{so}");
    // `check` agrees, on the file as written (its own numbering).
    let o = run(&["check", s(&input), s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stdout));
    assert!(text(&o.stdout).contains("cleaned original"));
}

/// Item 2: unreferenced vertices are dropped from output files unless --keep-numbering.
#[test]
fn outputs_drop_unreferenced_vertices_unless_asked() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "g.obj", &bumpy_obj(16, false));
    let (small, kept) = (d.path().join("small.obj"), d.path().join("kept.obj"));
    let o = run(&[
        "simplify",
        s(&input),
        s(&small),
        "--ratio",
        "0.1",
        "--no-measure",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = run(&[
        "simplify",
        s(&input),
        s(&kept),
        "--ratio",
        "0.1",
        "--no-measure",
        "--keep-numbering",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(v_lines(&kept), 17 * 17 + 1, "every input vertex, in place");
    let n = v_lines(&small);
    assert!(n < 17 * 17 / 5, "{n} vertices written for ~58 triangles");
    // Both check out against the input: numbering kept, or matched back by position.
    for (f, renumbered) in [(&kept, false), (&small, true)] {
        let o = run(&["check", s(&input), s(f)]);
        let so = text(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{so}");
        assert_eq!(so.contains("matched back"), renumbered, "{so}");
    }
}

/// Item 3: quads are split (counted), attributes are warned about and --help says they are
/// not carried.
#[test]
fn quads_are_triangulated_and_dropped_attributes_warned() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "q.obj", &bumpy_obj(10, true));
    let out = d.path().join("q-out.ply");
    let o = run(&["simplify", s(&input), s(&out), "--ratio", "0.25"]);
    let (so, se) = (text(&o.stdout), text(&o.stderr));
    assert_eq!(o.status.code(), Some(0), "{so}\n{se}");
    assert!(
        se.contains("100 polygon(s) with more than 3 corners split into 200 triangles"),
        "{se}"
    );
    assert!(
        se.contains("attributes are not carried")
            && se.contains("texture coordinates (vt)")
            && se.contains("normals (vn)"),
        "{se}"
    );
    assert!(so.contains("triangles in           200"), "{so}");
    let help = text(&run(&["simplify", "--help"]).stdout);
    assert!(help.contains("not carried"), "{help}");
    assert!(help.contains("n-gons"), "{help}");
}

/// Item 4: a bad output path or format fails at once, before the input is even read; STL is
/// written.
#[test]
fn output_is_checked_first_and_stl_is_written() {
    let d = tempfile::tempdir().unwrap();
    // The input does not exist: if the output were checked later, this would say so instead.
    let missing = d.path().join("missing.obj");
    for (out, says) in [
        (d.path().join("x.off"), "unknown mesh format"),
        (d.path().join("no/such/dir/x.obj"), "cannot create"),
    ] {
        let o = run(&["simplify", s(&missing), s(&out), "--ratio", "0.5"]);
        let se = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{se}");
        assert!(se.contains(says) && !se.contains("missing.obj"), "{se}");
    }
    let input = write(d.path(), "g.obj", &bumpy_obj(8, false));
    let stl = d.path().join("g.stl");
    let o = run(&["simplify", s(&input), s(&stl), "--ratio", "0.5"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let bytes = std::fs::read(&stl).unwrap();
    let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!(bytes.len(), 84 + 50 * n);
    assert!(n > 0 && n <= 64);
    // STL welds by position, in its own order: `check` matches it back.
    let o = run(&["check", s(&input), s(&stl)]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stdout));
}

/// Item 5: a reader that closes the pipe early does not make a command panic (exit 101).
#[test]
fn broken_pipe_is_not_a_panic() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "g.obj", &bumpy_obj(12, false));
    for args in [
        vec!["check", s(&input), s(&input), "--json"],
        vec!["check", s(&input), s(&input)],
        vec!["metro", s(&input), s(&input)],
        vec!["simplify", s(&input), "-", "--ratio", "0.5", "--no-measure"],
    ] {
        let mut child = bin()
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Read nothing: close the pipe before the child writes (it loads a file first).
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        let se = text(&o.stderr);
        assert!(!se.contains("panicked"), "{args:?}: {se}");
        assert_eq!(o.status.code(), Some(0), "{args:?}: {se}");
    }
}

/// Item 6: negative numbers are values, and every range error gives the range.
#[test]
fn numbers_out_of_range_say_the_range() {
    for (flag, v, range) in [
        ("--ratio", "-1", "accepted: above 0, at most 1"),
        ("--ratio", "2", "accepted: above 0, at most 1"),
        ("--ratio", "abc", "accepted: above 0, at most 1"),
        (
            "--max-error",
            "-0.5",
            "accepted: 0 or more, or a percentage",
        ),
        ("--max-error", "200%", "accepted: above 0 %, at most 100 %"),
        ("--max-turn", "200", "accepted: above 0, below 180"),
        ("--min-quality", "1", "accepted: 0 or more, below 1"),
        ("--lambda", "-2", "accepted: 0 or more"),
    ] {
        // --ratio with --target-triangles is refused as a conflict, so --ratio comes alone.
        let target: &[&str] = if flag == "--ratio" {
            &[]
        } else {
            &["--target-triangles", "9"]
        };
        let mut args = vec!["simplify", "a.obj", "b.obj"];
        args.extend_from_slice(target);
        args.extend_from_slice(&[flag, v]);
        let o = run(&args);
        let se = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {v}: {se}");
        assert!(!se.contains("unexpected argument"), "{flag} {v}: {se}");
        assert!(se.contains(range), "{flag} {v}: {se}");
    }
}

/// Item 7: no progress bar reaches a pipe (the bar is for terminals only; unit-tested in
/// `progress.rs`).
#[test]
fn no_progress_bar_on_a_pipe() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "g.obj", &bumpy_obj(30, false));
    let o = run(&[
        "simplify",
        s(&input),
        s(&d.path().join("o.obj")),
        "--ratio",
        "0.1",
    ]);
    assert_eq!(o.status.code(), Some(0));
    let se = text(&o.stderr);
    assert!(
        !se.contains('\r') && !se.contains("\x1b[") && !se.contains("samples"),
        "{se:?}"
    );
}

/// Item 8: --json (report, check and Metro in one object), --max-error, and `-` for stdin and
/// stdout.
#[test]
fn json_max_error_and_stdio() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "g.obj", &bumpy_obj(20, false));
    let out = d.path().join("o.obj");
    let o = run(&[
        "simplify",
        s(&input),
        s(&out),
        "--ratio",
        "0.2",
        "--json",
        "--measure",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["report"]["triangles_in"], 800);
    assert!(j["report"]["triangles_out"].as_u64().unwrap() <= 160);
    assert_eq!(j["report"]["target_reached"], true);
    assert_eq!(j["check"]["valid"], true);
    assert_eq!(j["check"]["against"], "cleaned input");
    assert!(j["metro"].is_object(), "{j}");
    assert_eq!(j["valid"], true);
    assert!(j["advice"].is_null(), "{j}");

    // --max-error alone (a percentage of the diagonal or a distance): a guaranteed bound; a
    // tighter one keeps more triangles, E_max stays within it, any cost.
    let mut kept = Vec::new();
    for (e, cost) in [("0.2%", "quadric"), ("2%", "quadric"), ("0.01", "normal")] {
        let o = run(&[
            "simplify",
            s(&input),
            s(&out),
            "--max-error",
            e,
            "--cost",
            cost,
            "--json",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let d = j["d_hold"].as_f64().unwrap();
        assert!(d > 0.0);
        let emax = j["report"]["max_error"].as_f64().unwrap();
        assert!(emax <= d, "{e}: {emax} > {d}");
        assert!(j["report"]["mean_error"].as_f64().unwrap() <= emax);
        assert_eq!(j["valid"], true);
        // The bound is the goal: stopping there is no shortfall.
        assert!(j["advice"].is_null(), "{j}");
        kept.push(j["report"]["triangles_out"].as_u64().unwrap());
    }
    assert!(kept[0] > kept[1], "{kept:?}");
    let o = run(&[
        "simplify",
        s(&input),
        s(&out),
        "--max-error",
        "0.01",
        "--quadric",
        "stored",
        "--placement",
        "optimal",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("subset"));

    // Standard input to standard output: the mesh on stdout, the report on stderr.
    let mut child = bin()
        .args(["simplify", "-", "-", "--ratio", "0.5"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(std::fs::read(&input).unwrap().as_slice())
        .unwrap();
    let o = child.wait_with_output().unwrap();
    let (so, se) = (text(&o.stdout), text(&o.stderr));
    assert_eq!(o.status.code(), Some(0), "{se}");
    let faces = so.lines().filter(|l| l.starts_with("f ")).count();
    assert!(
        so.starts_with("v ") && faces > 300 && faces <= 400,
        "{faces}"
    );
    assert!(
        se.contains("triangles out") && se.contains("=> VALID"),
        "{se}"
    );
    // --json with `-` as output would mix the two.
    let o = run(&["simplify", s(&input), "-", "--ratio", "0.5", "--json"]);
    assert_eq!(o.status.code(), Some(2));
}

/// A run that stops short says which limit stopped it, the option that relaxes it and the
/// clustering fallback, in the text and in the JSON; relaxed as advised, it reaches the target.
#[test]
fn stopping_short_says_why_and_what_to_do() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "g.obj", &bumpy_obj(20, false));
    let out = d.path().join("o.obj");
    let args = [
        "simplify",
        s(&input),
        s(&out),
        "--ratio",
        "0.05",
        "--no-measure",
    ];
    let o = run(&[&args[..], &["--max-turn", "1", "--json"]].concat());
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["report"]["target_reached"], false, "{j}");
    let a = &j["advice"];
    assert_eq!(a["limit"], "normal_turn", "{a}");
    assert_eq!(a["relax"][0]["option"], "--max-turn", "{a}");
    let target = j["report"]["target_triangles"].as_u64().unwrap();
    assert_eq!(
        a["fallback"].as_str().unwrap(),
        format!(
            "tinydecimate cluster {} {} --target-triangles {target}",
            s(&input),
            s(&out)
        )
    );
    assert!(a["fallback_then_collapse"]
        .as_str()
        .unwrap()
        .ends_with(&format!(
            "--target-triangles {} --then-collapse {target}",
            2 * target
        )));
    let o = run(&[&args[..], &["--max-turn", "1"]].concat());
    let t = text(&o.stdout);
    for line in [
        "stopped short",
        "limit                  normal_turn",
        "relax                  --max-turn 120",
        "fallback               tinydecimate cluster",
    ] {
        assert!(t.contains(line), "{line}: {t}");
    }
    // As advised.
    let o = run(&[&args[..], &["--max-turn", "120", "--json"]].concat());
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["report"]["target_reached"], true, "{j}");
    assert!(j["advice"].is_null());
}

/// Vertex decimation's fill (`Fill::Fit`, `--operator vertex-decimation`) against the paper's
/// as written (`Fill::Shape`, `--operator vertex-decimation-shape`) on the cow at 10 %: both
/// valid and at the target; the fitted fill's Metro mean error is under half the paper's
/// (measured 0.26 % against 1.14 % of the diagonal). Fails if the fill goes back to loop
/// splitting alone or the key to Schroeder's distance.
#[test]
fn vertex_decimation_fill_fits_the_surface() {
    let cow = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/cow.obj");
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o.obj");
    let mut mean = Vec::new();
    for op in ["vertex-decimation", "vertex-decimation-shape"] {
        let o = run(&[
            "simplify",
            s(&cow),
            s(&out),
            "--ratio",
            "0.1",
            "--operator",
            op,
            "--json",
            "--measure",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(j["valid"], true, "{op}");
        assert_eq!(j["report"]["target_reached"], true, "{op}");
        mean.push(j["metro"]["symmetric_mean_pct"].as_f64().unwrap());
    }
    assert!(
        mean[0] < mean[1] / 2.0,
        "fit {} vs shape {}",
        mean[0],
        mean[1]
    );
}

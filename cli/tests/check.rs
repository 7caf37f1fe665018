//! `tinydecimate check` judges what `tinydecimate simplify` promises, with the same defaults and the
//! same validity function (`tinydecimate_cli::check::verdict`), and names cracks; `simplify` measures
//! the Metro error only with `--measure`; its report keeps one line per figure on glTF input.
//! Each test runs the built binary.

mod common;
use common::{fixture, run, s, text};

/// Every output `simplify` calls VALID with its defaults passes `check` with its defaults:
/// multi-part models (parts pruned), seam-split assets (seams welded), a scan with holes and
/// two clean meshes, at 10 % and 25 %. Before `check` learnt `--seams` and `--parts` it
/// refused wuson and pr2_sensor_mount (components) and suzanne_seams (pinches, loops).
#[test]
fn simplify_default_outputs_pass_check() {
    let d = tempfile::tempdir().unwrap();
    let mut failed = Vec::new();
    for mesh in [
        "wuson.obj",
        "pr2_sensor_mount.obj",
        "suzanne_seams.obj",
        "pins.obj",
        "stanford_bunny.obj",
        "tray_bottom.obj",
        "cow.obj",
    ] {
        for ratio in ["0.1", "0.25"] {
            let input = fixture(mesh);
            let out = d.path().join(format!("{mesh}-{ratio}.obj"));
            let o = run(&["simplify", s(&input), s(&out), "--ratio", ratio]);
            let so = text(&o.stdout);
            assert_eq!(o.status.code(), Some(0), "{mesh} {ratio}: {so}");
            assert!(so.contains("=> VALID"), "{mesh} {ratio}: {so}");
            let c = run(&["check", s(&input), s(&out)]);
            if c.status.code() != Some(0) {
                failed.push(format!("{mesh} {ratio}:\n{}", text(&c.stdout)));
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// A crack: suzanne_seams simplified with `--seams split` (each side of a UV seam shortened
/// on its own, and whole charts pruned) is valid as split, which `simplify` says and
/// `check --seams split` repeats; against the default promise (seams welded) `check` exits 1
/// and names the cracks, in text and JSON.
#[test]
fn a_cracked_output_fails_with_the_crack_named() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("suzanne_seams.obj");
    let out = d.path().join("split.obj");
    let o = run(&[
        "simplify",
        s(&input),
        s(&out),
        "--ratio",
        "0.25",
        "--seams",
        "split",
        "--keep-numbering",
    ]);
    let so = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{so}");
    assert!(
        so.contains("seams split") && so.contains("=> VALID"),
        "{so}"
    );
    let c = run(&["check", s(&input), s(&out), "--seams", "split"]);
    assert_eq!(c.status.code(), Some(0), "{}", text(&c.stdout));

    let c = run(&["check", s(&input), s(&out)]);
    let t = text(&c.stdout);
    assert_eq!(c.status.code(), Some(1), "{t}");
    let row = t
        .lines()
        .find(|l| l.trim_start().starts_with("cracks (boundary edges)"))
        .unwrap_or_else(|| panic!("no cracks row: {t}"));
    assert!(row.ends_with("FAIL"), "{row}");
    let named = t
        .lines()
        .find(|l| l.trim_start().starts_with("crack at edge "))
        .unwrap_or_else(|| panic!("no crack named: {t}"));
    assert!(
        named.contains("a boundary edge where the input had surface"),
        "{named}"
    );
    let c = run(&["check", s(&input), s(&out), "--json"]);
    assert_eq!(c.status.code(), Some(1));
    let j: serde_json::Value = serde_json::from_slice(&c.stdout).unwrap();
    assert!(j["validity"]["cracks"].as_u64().unwrap() > 0, "{j}");
    assert!(
        j["defects"]
            .as_array()
            .unwrap()
            .iter()
            .any(|d| d.as_str().unwrap().starts_with("crack at edge")),
        "{j}"
    );
    assert_eq!(j["seams"], "Weld");
}

/// Parts pruned by `simplify --parts prune` (the default of both engines) pass `check`'s
/// default; with `--parts keep` the same file fails on its number of components.
#[test]
fn parts_keep_refuses_a_pruned_output() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("pr2_sensor_mount.obj");
    let out = d.path().join("o.obj");
    let o = run(&[
        "simplify",
        s(&input),
        s(&out),
        "--ratio",
        "0.1",
        "--parts",
        "prune",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let pruned = j["report"]["parts_removed"].as_u64().unwrap();
    assert!(pruned > 0, "{j}");
    let c = run(&["check", s(&input), s(&out)]);
    assert_eq!(c.status.code(), Some(0), "{}", text(&c.stdout));
    let c = run(&["check", s(&input), s(&out), "--parts", "keep"]);
    let t = text(&c.stdout);
    assert_eq!(c.status.code(), Some(1), "{t}");
    assert!(
        t.lines()
            .any(|l| l.trim() == format!("components 35 -> {}", 35 - pruned)),
        "{t}"
    );
}

/// Metro is opt-in: the default run checks the result, prints no Metro figure and says in
/// one line how to get them; `--measure` prints them; `--json` has `metro` null or an object.
#[test]
fn metro_only_with_measure() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("cow.obj");
    let out = d.path().join("o.obj");
    let args = ["simplify", s(&input), s(&out), "--ratio", "0.25"];
    let o = run(&args);
    let t = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(t.contains("=> VALID"), "{t}");
    assert!(!t.contains("metro") && !t.contains("Hausdorff"), "{t}");
    let hint: Vec<&str> = t.lines().filter(|l| l.contains("--measure")).collect();
    assert_eq!(
        hint,
        ["error: not measured (--measure adds the Metro error, input vs output)"],
        "{t}"
    );
    let o = run(&[&args[..], &["--measure"]].concat());
    let t = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(
        t.contains("metro (input vs output):") && t.contains("Hausdorff (symmetric)"),
        "{t}"
    );
    assert!(!t.contains("not measured"), "{t}");
    // JSON, both ways.
    let o = run(&[&args[..], &["--json"]].concat());
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(j["metro"].is_null(), "{j}");
    assert_eq!(j["check"]["valid"], true);
    let o = run(&[&args[..], &["--json", "--measure"]].concat());
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(j["metro"]["hausdorff_pct"].as_f64().unwrap() > 0.0, "{j}");
    // Old scripts' --no-measure is still accepted.
    let o = run(&[&args[..], &["--no-measure"]].concat());
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
}

/// A GLB of one primitive, a bumpy `n` x `n` grid (positions and indices only).
fn bumpy_glb(n: usize) -> Vec<u8> {
    let mut pos: Vec<f32> = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            let (fx, fy) = (x as f32 / n as f32, y as f32 / n as f32);
            pos.extend([fx, fy, 0.15 * (fx * 23.0).sin() * (fy * 19.0).cos()]);
        }
    }
    let mut idx: Vec<u32> = Vec::new();
    let v = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    for y in 0..n {
        for x in 0..n {
            idx.extend([v(x, y), v(x + 1, y), v(x + 1, y + 1)]);
            idx.extend([v(x, y), v(x + 1, y + 1), v(x, y + 1)]);
        }
    }
    let mut bin: Vec<u8> = pos.iter().flat_map(|x| x.to_le_bytes()).collect();
    let pos_len = bin.len();
    bin.extend(idx.iter().flat_map(|i| i.to_le_bytes()));
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos_len},
            {"buffer": 0, "byteOffset": pos_len, "byteLength": bin.len() - pos_len}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": pos.len() / 3, "type": "VEC3",
             "min": [0.0, 0.0, -0.15], "max": [1.0, 1.0, 0.15]},
            {"bufferView": 1, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}
        ]
    });
    let mut j = serde_json::to_vec(&json).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + j.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&j);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(&bin);
    out
}

/// On a GLB that stops at its error limit, every line of the report stands alone: the
/// verdict (and with `--measure` the Metro figures) on a `check` line of its own, not glued
/// onto the advice's `relax` or the report's `error limit` line.
#[test]
fn glb_report_lines_stand_alone() {
    let d = tempfile::tempdir().unwrap();
    let input = d.path().join("bumpy.glb");
    std::fs::write(&input, bumpy_glb(24)).unwrap();
    let out = d.path().join("o.glb");
    for extra in [&[][..], &["--measure"][..]] {
        let o = run(&[
            &["simplify", s(&input), s(&out), "--ratio", "0.02"][..],
            extra,
        ]
        .concat());
        let t = text(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{t}{}", text(&o.stderr));
        assert!(t.contains("stop                   ErrorLimit"), "{t}");
        assert!(
            t.lines().any(|l| l.trim_start().starts_with("relax ")),
            "{t}"
        );
        let error_limit = t
            .lines()
            .find(|l| l.trim_start().starts_with("error limit "))
            .unwrap_or_else(|| panic!("{t}"));
        // The verdict is the check line, alone.
        let verdicts: Vec<&str> = t.lines().filter(|l| l.contains("valid")).collect();
        assert_eq!(verdicts.len(), 1, "{t}");
        assert!(
            verdicts[0].starts_with("  check                  valid"),
            "{t}"
        );
        assert!(!error_limit.contains("Metro"), "{error_limit}");
        let metro = t.lines().filter(|l| l.contains("Metro max")).count();
        assert_eq!(metro, usize::from(!extra.is_empty()), "{t}");
        if metro == 1 {
            assert!(verdicts[0].contains("Metro max"), "{t}");
        }
    }
}

/// A bumpy grid with texture coordinates, its left and right halves in two material groups
/// that share the middle column of vertices.
fn two_material_obj(n: usize) -> String {
    let mut o = String::from("mtllib m.mtl\n");
    for y in 0..=n {
        for x in 0..=n {
            let z = 0.1 * (x as f32 * 0.7).sin() * (y as f32 * 0.5).cos();
            o += &format!("v {} {} {z}\n", x as f32 / n as f32, y as f32 / n as f32);
        }
    }
    for y in 0..=n {
        for x in 0..=n {
            o += &format!("vt {} {}\n", x as f32 / n as f32, y as f32 / n as f32);
        }
    }
    let v = |x: usize, y: usize| y * (n + 1) + x + 1;
    for (mat, xs) in [("a", 0..n / 2), ("b", n / 2..n)] {
        o += &format!("usemtl {mat}\n");
        for y in 0..n {
            for x in xs.clone() {
                let (a, b, c, d) = (v(x, y), v(x + 1, y), v(x + 1, y + 1), v(x, y + 1));
                o += &format!("f {a}/{a} {b}/{b} {c}/{c}\nf {a}/{a} {c}/{c} {d}/{d}\n");
            }
        }
    }
    o
}

/// `simplify` simplifies a model's material groups together and judges them as one surface;
/// `check` judges it the same way, so simplify's default output passes. With
/// `--per-primitive` each group is simplified on its own: their shared border opens, which
/// `check` then calls a defect, and `check --per-primitive` judges each group on its own, as
/// that run did, saying that the border opened. A group broken on its own fails either way.
#[test]
fn material_groups_are_judged_as_simplify_judges_them() {
    let d = tempfile::tempdir().unwrap();
    let input = d.path().join("two.obj");
    std::fs::write(&input, two_material_obj(30)).unwrap();
    std::fs::write(d.path().join("m.mtl"), "newmtl a\nnewmtl b\n").unwrap();
    let out = d.path().join("out.obj");
    let o = run(&["simplify", s(&input), s(&out), "--ratio", "0.1"]);
    let so = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{so}");
    assert!(so.contains("all 2 material groups"), "{so}");
    assert!(so.contains("0 of them new"), "{so}");
    let c = run(&["check", s(&input), s(&out)]);
    let co = text(&c.stdout);
    assert_eq!(c.status.code(), Some(0), "{co}");

    let apart = d.path().join("apart.obj");
    let o = run(&[
        "simplify",
        s(&input),
        s(&apart),
        "--ratio",
        "0.1",
        "--per-primitive",
    ]);
    let so = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{so}");
    assert!(so.contains("material a"), "{so}");
    assert!(so.contains("(gaps between parts)"), "{so}");
    let c = run(&["check", s(&input), s(&apart)]);
    let co = text(&c.stdout);
    assert_eq!(c.status.code(), Some(1), "{co}");
    let c = run(&["check", s(&input), s(&apart), "--per-primitive"]);
    let co = text(&c.stdout);
    assert_eq!(c.status.code(), Some(0), "{co}");
    assert!(co.contains("each of the 2 parts on its own"), "{co}");
    assert!(
        co.contains("material a: valid") && co.contains("material b: valid"),
        "{co}"
    );
    assert!(co.contains("borders between parts opened"), "{co}");

    // Group b with a triangle repeated: that group is invalid, and so is the file.
    for (simplified, extra) in [(&out, None), (&apart, Some("--per-primitive"))] {
        let bad = d.path().join("bad.obj");
        let written = std::fs::read_to_string(simplified).unwrap();
        let last_face = written.lines().rev().find(|l| l.starts_with("f ")).unwrap();
        std::fs::write(&bad, format!("{written}{last_face}\n")).unwrap();
        let mut a = vec!["check", s(&input), s(&bad)];
        a.extend(extra);
        let c = run(&a);
        let co = text(&c.stdout);
        assert_eq!(c.status.code(), Some(1), "{co}");
        if extra.is_some() {
            assert!(co.contains("material b: NOT valid"), "{co}");
        }
    }
}

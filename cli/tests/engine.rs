//! `tinydecimate simplify --engine fast` and `--engine lean`: the fast and the lean mode
//! (`tinydecimate::pipeline`) from the command line. Their outputs pass the shared check with
//! `check`'s defaults (seams welded, parts may vanish whole), the error limit stops them as it
//! stops the exact engine, and what they cannot run is refused with the option named. Each
//! test runs the built binary, once per engine.

mod common;
use common::{fixture, run, s, text};

/// The pipeline's engines and their name in the JSON (`engine`).
const ENGINES: [(&str, &str); 2] = [("fast", "Fast"), ("lean", "Lean")];

/// A clean scan, a seam-split asset (welded by position), a raw CAD export and a multi-part
/// model at 10 %: `simplify` says VALID, `check` agrees, and the JSON names the engine.
#[test]
fn fast_and_lean_outputs_pass_check() {
    let d = tempfile::tempdir().unwrap();
    let mut failed = Vec::new();
    for (engine, json_name) in ENGINES {
        for mesh in [
            "stanford_bunny.obj",
            "suzanne_seams.obj",
            "pins.obj",
            "wuson.obj",
        ] {
            let input = fixture(mesh);
            let out = d.path().join(format!("{engine}-{mesh}"));
            let o = run(&[
                "simplify",
                s(&input),
                s(&out),
                "--ratio",
                "0.1",
                "--engine",
                engine,
                "--json",
            ]);
            let so = text(&o.stdout);
            assert_eq!(o.status.code(), Some(0), "{engine} {mesh}: {so}");
            let j: serde_json::Value = serde_json::from_str(&so).unwrap();
            assert_eq!(j["engine"], json_name, "{engine} {mesh}");
            assert_eq!(j["valid"], true, "{engine} {mesh}");
            let c = run(&["check", s(&input), s(&out)]);
            if c.status.code() != Some(0) {
                failed.push(format!("{engine} {mesh}:\n{}", text(&c.stdout)));
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// The bunny to 1 % with a limit of 0.05 % of the diagonal stops on the limit, short of the
/// target, with every collapse made under it; without a limit it reaches the count.
#[test]
fn the_error_limit_stops_the_fast_and_lean_engines() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("stanford_bunny.obj");
    let out = d.path().join("b.obj");
    for (engine, _) in ENGINES {
        let report = |limit: &str| {
            engine_json(engine, &input, &out, "0.01", &["--error-limit", limit])["report"].clone()
        };
        let free = report("none");
        assert_eq!(free["stop"], "Target", "{engine}: {free}");
        let limited = report("0.05%");
        assert_eq!(limited["stop"], "ErrorLimit", "{engine}: {limited}");
        assert!(
            limited["over_limit"].as_u64().unwrap() > 0,
            "{engine}: {limited}"
        );
        assert!(
            limited["triangles_out"].as_u64().unwrap()
                > 2 * free["triangles_out"].as_u64().unwrap(),
            "{engine}: {limited}"
        );
        // 0.05 % of the bunny's diagonal (about 0.25 units): every collapse under it.
        let diagonal = 0.2502f64;
        assert!(
            limited["collapse_error"].as_f64().unwrap() <= 0.0005 * diagonal * 1.001,
            "{engine}: {limited}"
        );
    }
}

/// What the fast and the lean mode do not run is refused before any work, the option named.
#[test]
fn what_the_fast_and_lean_engines_cannot_run_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("cow.obj");
    let out = d.path().join("c.obj");
    // Attributes: kept, the seams welded with their wedges (not refused).
    let textured = textured_quad(d.path());
    for (engine, _) in ENGINES {
        for (extra, named) in [
            (&["--schedule", "passes"][..], "--schedule"),
            (&["--quadric", "stored"][..], "--quadric"),
            (&["--operator", "triangle"][..], "--operator"),
            (&["--max-error", "1%"][..], "--max-error"),
            (&["--cost", "normal"][..], "--cost"),
            (&["--lambda", "1"][..], "--lambda"),
        ] {
            let mut args = vec![
                "simplify",
                s(&input),
                s(&out),
                "--ratio",
                "0.5",
                "--engine",
                engine,
            ];
            args.extend_from_slice(extra);
            let o = run(&args);
            assert_ne!(o.status.code(), Some(0), "{engine} {extra:?}");
            let e = text(&o.stderr);
            assert!(e.contains(named), "{engine} {extra:?}: {e}");
            assert!(!out.exists(), "{engine} {extra:?}: an output was written");
        }
        let o = run(&[
            "simplify",
            s(&textured),
            s(&out),
            "--ratio",
            "0.5",
            "--engine",
            engine,
        ]);
        assert_eq!(o.status.code(), Some(0), "{engine}: {}", text(&o.stderr));
        let written = std::fs::read_to_string(&out).unwrap();
        assert!(
            written.contains("\nvt "),
            "{engine}: texture coordinates lost"
        );
        std::fs::remove_file(&out).unwrap();
    }
}

/// `--engine auto` (the default) runs the fast mode, and the exact engine when an option only
/// it takes is given or the mesh is double-sided somewhere.
#[test]
fn auto_picks_the_fast_mode_unless_the_run_needs_the_exact_engine() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o.obj");
    let engine = |input: &std::path::Path, extra: &[&str]| {
        let mut args = vec!["simplify", s(input), s(&out), "--ratio", "0.5", "--json"];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{extra:?}: {}", text(&o.stderr));
        let j: serde_json::Value = serde_json::from_str(&text(&o.stdout)).unwrap();
        j["engine"].as_str().unwrap().to_string()
    };
    let cow = fixture("cow.obj");
    assert_eq!(engine(&cow, &[]), "Fast");
    assert_eq!(engine(&cow, &["--parts", "keep"]), "Fast");
    assert_eq!(engine(&cow, &["--parts", "prune"]), "Fast");
    assert_eq!(engine(&cow, &["--schedule", "batched"]), "Exact");
    assert_eq!(engine(&cow, &["--engine", "exact"]), "Exact");
    // A sheet of two triangles with its back: double-sided.
    let sheet = d.path().join("sheet.obj");
    std::fs::write(
        &sheet,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\nf 1 3 2\nf 1 4 3\n",
    )
    .unwrap();
    assert_eq!(engine(&sheet, &[]), "Exact");
}

/// The fandisk (a CAD model: flat and cylindrical patches) to 50 %: every collapse it needs
/// lies in a patch, so the result stays within 0.005 % of the diagonal of the input (Metro,
/// both directions). Quadrics evaluated in a global frame in `f32` lose such errors to
/// rounding; the vertex-centred ones do not.
#[test]
fn collapses_within_flat_patches_cost_no_error() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("fandisk.obj");
    let out = d.path().join("f.obj");
    for (engine, _) in ENGINES {
        let j = engine_json(engine, &input, &out, "0.5", &["--measure"]);
        let h = j["metro"]["hausdorff_pct"].as_f64().unwrap();
        assert!(
            h < 0.005,
            "{engine}: Hausdorff distance {h} % of the diagonal"
        );
    }
}

/// The CAD assembly with pins to 10 %: its small closed parts hold it above the target with
/// `--parts keep`; by default they go whole (the report counts them), the target is reached
/// and `check` accepts the output.
#[test]
fn the_fast_and_lean_engines_prune_parts() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("pr2_sensor_mount.obj");
    let out = d.path().join("p.obj");
    for (engine, _) in ENGINES {
        let kept = engine_json(engine, &input, &out, "0.1", &["--parts", "keep"]);
        assert_eq!(kept["report"]["parts_removed"], 0, "{engine}");
        assert_eq!(kept["report"]["target_reached"], false, "{engine}");
        let pruned = engine_json(engine, &input, &out, "0.1", &[]);
        assert!(
            pruned["report"]["parts_removed"].as_u64().unwrap() > 0,
            "{engine}: {}",
            pruned["report"]
        );
        assert_eq!(pruned["report"]["target_reached"], true, "{engine}");
        assert_eq!(pruned["valid"], true, "{engine}");
        let c = run(&["check", s(&input), s(&out)]);
        assert_eq!(c.status.code(), Some(0), "{engine}: {}", text(&c.stdout));
    }
}

/// A build without meshoptimizer (`cargo install --path cli`, the default) refuses
/// `--meshopt-out` before reading anything, naming the install line that has it.
#[cfg(not(feature = "meshopt"))]
#[test]
fn meshopt_out_without_the_feature_names_the_install_line() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("ours.obj");
    let theirs = d.path().join("theirs.obj");
    let o = run(&[
        "simplify",
        s(&fixture("cow.obj")),
        s(&out),
        "--ratio",
        "0.25",
        "--meshopt-out",
        s(&theirs),
    ]);
    assert_ne!(o.status.code(), Some(0));
    assert!(
        text(&o.stderr).contains("cargo install --path cli --features meshopt"),
        "{}",
        text(&o.stderr)
    );
    assert!(!out.exists() && !theirs.exists());
}

/// `--meshopt-out` writes meshoptimizer's result at the count the run reached, a mesh `check`
/// reads; a mesh with attributes is refused, naming the option. (Feature `meshopt`, which the
/// workspace turns on through host-sim.)
#[cfg(feature = "meshopt")]
#[test]
fn meshoptimizer_s_result_is_written_beside_ours() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("cow.obj");
    let (out, theirs) = (d.path().join("o.obj"), d.path().join("m.obj"));
    let j = engine_json("fast", &input, &out, "0.25", &["--meshopt-out", s(&theirs)]);
    let ours = j["report"]["triangles_out"].as_u64().unwrap();
    let text_of = std::fs::read_to_string(&theirs).unwrap();
    let n = text_of.lines().filter(|l| l.starts_with("f ")).count() as u64;
    assert!(
        n > 0 && n <= ours && n * 10 >= ours * 9,
        "{n} against {ours}"
    );
    let textured = textured_quad(d.path());
    let o = run(&[
        "simplify",
        s(&textured),
        s(&out),
        "--ratio",
        "0.5",
        "--meshopt-out",
        s(&theirs),
    ]);
    assert_ne!(o.status.code(), Some(0));
    assert!(
        text(&o.stderr).contains("--meshopt-out"),
        "{}",
        text(&o.stderr)
    );
}

/// A textured quad (two triangles with texture coordinates) as `quad.obj` in `dir`.
fn textured_quad(dir: &std::path::Path) -> std::path::PathBuf {
    let path = dir.join("quad.obj");
    std::fs::write(
        &path,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    path
}

/// `simplify INPUT OUT --ratio R --engine ENGINE --json EXTRA...`, which must succeed; its
/// JSON.
fn engine_json(
    engine: &str,
    input: &std::path::Path,
    out: &std::path::Path,
    ratio: &str,
    extra: &[&str],
) -> serde_json::Value {
    let mut args = vec![
        "simplify",
        s(input),
        s(out),
        "--ratio",
        ratio,
        "--engine",
        engine,
        "--json",
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    serde_json::from_str(&text(&o.stdout)).unwrap()
}

/// `--integer` on the cow, with each engine: the summary names the grid's cell, every output
/// coordinate is a whole number of cells (the grid's positions, its origin a multiple of the
/// cell), the output is valid; with the exact engine it is refused.
#[test]
fn integer_runs_name_their_grid_and_write_its_positions() {
    let d = tempfile::tempdir().unwrap();
    let input = fixture("cow.obj");
    let out = d.path().join("cow.obj");
    for (engine, _) in ENGINES {
        let o = run(&[
            "simplify",
            s(&input),
            s(&out),
            "--ratio",
            "0.25",
            "--engine",
            engine,
            "--integer",
        ]);
        let so = text(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{engine}: {so}");
        assert!(so.contains("=> VALID"), "{engine}: {so}");
        let cell: f64 = so
            .split("15-bit grid (cell ")
            .nth(1)
            .and_then(|rest| rest.split(';').next())
            .and_then(|c| c.parse().ok())
            .unwrap_or_else(|| panic!("{engine}: no grid cell in {so}"));
        let written = std::fs::read_to_string(&out).unwrap();
        let mut coordinates = 0;
        for line in written.lines().filter(|l| l.starts_with("v ")) {
            for x in line.split_whitespace().skip(1) {
                let k = f64::from(x.parse::<f32>().unwrap()) / cell;
                assert_eq!(
                    k,
                    k.round(),
                    "{engine}: {line} is off the grid of cell {cell}"
                );
                coordinates += 1;
            }
        }
        assert!(coordinates > 3 * 700, "{engine}: {coordinates} coordinates");
    }
    let o = run(&[
        "simplify",
        s(&input),
        s(&out),
        "--integer",
        "--engine",
        "exact",
    ]);
    assert_ne!(o.status.code(), Some(0));
    assert!(text(&o.stderr).contains("--integer"), "{}", text(&o.stderr));
}

/// `--integer` on meshes with attributes: an OBJ with texture coordinates and vertex colours, a
/// PLY with colours and the glTF truck all simplify valid; the OBJ's positions are written as
/// the grid's (whole cells, the cell the power of two at or above the extent / 32 766), with
/// each `v` line's colour kept.
#[test]
fn integer_runs_carry_attributes_and_write_the_grid() {
    let d = tempfile::tempdir().unwrap();
    let n = 10;
    let (mut obj, mut ply_vertices, mut faces) = (String::new(), String::new(), Vec::new());
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 * 0.37, j as f32 * 0.41);
            let z = 0.3 * (i as f32 * 0.7).sin() * (j as f32 * 0.5).cos();
            obj.push_str(&format!("v {x} {y} {z} 0.5 0.25 0.125\n"));
            ply_vertices.push_str(&format!("{x} {y} {z} {} {} 7\n", i * 20, j * 20));
        }
    }
    for j in 0..=n {
        for i in 0..=n {
            obj.push_str(&format!(
                "vt {} {}\n",
                i as f32 / n as f32,
                j as f32 / n as f32
            ));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            faces.push([a, a + 1, a + n + 2]);
            faces.push([a, a + n + 2, a + n + 1]);
        }
    }
    for f in &faces {
        let [a, b, c] = f.map(|v| v + 1);
        obj.push_str(&format!("f {a}/{a} {b}/{b} {c}/{c}\n"));
    }
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n{ply_vertices}",
        (n + 1) * (n + 1),
        faces.len()
    );
    for [a, b, c] in &faces {
        ply.push_str(&format!("3 {a} {b} {c}\n"));
    }
    let (obj_in, ply_in) = (d.path().join("in.obj"), d.path().join("in.ply"));
    std::fs::write(&obj_in, obj).unwrap();
    std::fs::write(&ply_in, ply).unwrap();
    let truck = fixture("CesiumMilkTruck.glb");
    for (input, out) in [
        (obj_in.clone(), d.path().join("out.obj")),
        (ply_in, d.path().join("out.ply")),
        (truck, d.path().join("out.glb")),
    ] {
        let o = run(&[
            "simplify",
            s(&input),
            s(&out),
            "--ratio",
            "0.25",
            "--integer",
        ]);
        let so = text(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{}: {so}", input.display());
        assert!(
            so.contains("in integers: the positions put on a 15-bit grid"),
            "{so}"
        );
        assert!(!so.contains("NOT valid"), "{so}");
    }
    // A PLY with integer coordinates cannot hold the grid's positions: refused, named.
    let int_ply = d.path().join("int.ply");
    std::fs::write(
        &int_ply,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty int x\nproperty int y\n\
         property int z\nproperty uchar red\nelement face 2\n\
         property list uchar int vertex_indices\nend_header\n0 0 0 1\n3 0 0 1\n3 3 1 1\n\
         0 3 0 1\n3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    let int_out = d.path().join("int-out.ply");
    let o = run(&[
        "simplify",
        s(&int_ply),
        s(&int_out),
        "--ratio",
        "0.5",
        "--integer",
    ]);
    assert_ne!(o.status.code(), Some(0));
    assert!(
        text(&o.stderr).contains("not a float property"),
        "{}",
        text(&o.stderr)
    );
    // The input's largest extent is 10 · 0.41 (y): the cell is 2⁻¹², the power of two at or
    // above 4.1 / 32 766.
    let cell = (4.1f64 / 32_766.0).log2().ceil().exp2();
    let written = std::fs::read_to_string(d.path().join("out.obj")).unwrap();
    let lines: Vec<&str> = written.lines().filter(|l| l.starts_with("v ")).collect();
    assert!(lines.len() > 20, "{written}");
    for line in lines {
        let t: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(
            t[4..],
            ["0.5", "0.25", "0.125"],
            "{line}: the colour is kept"
        );
        for x in &t[1..4] {
            let k = f64::from(x.parse::<f32>().unwrap()) / cell;
            assert_eq!(k, k.round(), "{line} is off the grid of cell {cell}");
        }
    }
}

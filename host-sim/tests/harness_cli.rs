//! The `host-sim` command line (the harness: bench, golden files, QEMU, the demo) as a
//! contributor meets it: its help and its refusals, on the built binary.

use std::path::Path;

fn run(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .output()
        .unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Every subcommand's `--help`.
fn all_help() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let cmds: &[&[&str]] = &[
        &[],
        &["bench"],
        &["qemu"],
        &["golden"],
        &["demo"],
        &["stream"],
        &["bound-table"],
        &["run-elf"],
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

/// Internal labels (issue numbers, the papers' seed numbers) are not in the help texts, and
/// `run-elf` names the example that exists.
#[test]
fn no_internal_labels_in_help() {
    for (cmd, help) in all_help() {
        let low = help.to_lowercase();
        for w in ["issue ", "seed "] {
            let labelled = low.match_indices(w).any(|(i, _)| {
                low[i + w.len()..]
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_ascii_digit())
            });
            assert!(!labelled, "host-sim {cmd} --help: {help}");
        }
    }
    let help = text(&run(&["run-elf", "--help"]).stdout);
    assert!(help.contains("examples/cortex-m4f"), "{help}");
    assert!(!help.contains("examples/firmware"), "{help}");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    assert!(root.join("examples/cortex-m4f").is_dir());
}

/// `stream` checks, before building or running anything, that the file is a progressive
/// stream and that the board holds it, and says what fits.
#[test]
fn stream_says_why_before_running() {
    let d = tempfile::tempdir().unwrap();
    // A 60 x 60 grid of quads (the golden cases' generator): 3 721 vertices.
    let g = meshfmt::golden::bumpy_grid(60);
    let mesh = host_sim::io::MeshData {
        positions: g.positions,
        triangles: g.triangles,
    };
    let obj = d.path().join("g.obj");
    host_sim::io::save(&obj, &mesh).unwrap();
    let o = run(&["stream", s(&obj)]);
    let e = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("not a progressive stream"), "{e}");
    assert!(!e.contains("malformed output"), "{e}");
    let config = tinydecimate::Config::new().with_ratio(0.02);
    let (bytes, _, _) = host_sim::pm::encode_mesh(&mesh, &config, false, 256).unwrap();
    let tdpm = d.path().join("g.tdpm");
    std::fs::write(&tdpm, bytes).unwrap();
    for (board, holds) in [
        ("mps2-an386", "up to 3000 vertices"),
        ("microbit", "up to 44 vertices"),
    ] {
        let o = run(&["stream", s(&tdpm), "--board", board]);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(
            e.contains("3721 vertices")
                && e.contains(holds)
                && e.contains("Encode a mesh that fits"),
            "{e}"
        );
    }
}

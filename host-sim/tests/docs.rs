//! The words of README.md, the scripts and the sources: citations and figures that were wrong
//! once (issue 11, items 11 and 12) must not come back.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Every text file the citations and figures live in: README, docs, scripts and all `.rs`
/// files of the library, the tests and host-sim (firmware included).
fn texts() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = [
        "src",
        "tests",
        "host-sim/src",
        "host-sim/firmware/src",
        "scripts",
        "docs",
    ]
    .iter()
    .map(|d| root().join(d))
    .collect();
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("rs" | "md" | "sh")
            ) {
                if let Ok(s) = std::fs::read_to_string(&p) {
                    out.push((p.display().to_string(), s));
                }
            }
        }
    }
    out.push(("README.md".into(), read("README.md")));
    out
}

/// Item 11: seed 000 is Cheng, Pan and Shi (not Hoppe), seed 001 is Zhu, Wang and Meng (not
/// Garland-Heckbert); the link condition is seed 000 §3.2(1).
#[test]
fn seed_citations() {
    let this = file!();
    for (name, text) in texts() {
        if name.ends_with(this.rsplit('/').next().unwrap()) {
            continue;
        }
        for bad in [
            "Hoppe",
            "Garland-Heckbert",
            "Garland and Heckbert",
            "§3.1-3.3",
        ] {
            assert!(!text.contains(bad), "{name} still says {bad:?}");
        }
        for line in text.lines() {
            if line.contains("§3.1") {
                assert!(
                    line.contains("irregular") || line.contains("(§3.1)"),
                    "{name}: §3.1 of seed 000 is the vertex classification: {line}"
                );
            }
        }
    }
    let legality = read("src/legality.rs");
    // The link rule's row of `RULES`: its `source` follows its `name`.
    let link = legality
        .split("name: \"link\",")
        .nth(1)
        .and_then(|row| row.lines().find(|l| l.trim_start().starts_with("source:")))
        .unwrap();
    assert!(link.contains("Cheng, Pan and Shi §3.2(1)"), "{link}");
    let readme = read("README.md");
    assert!(readme.contains("Cheng, Pan and Shi"));
    assert!(readme.contains("§3.2(1)"));
    assert!(read("host-sim/src/metro.rs").contains("Zhu, Wang and Meng"));
}

/// Item 12: stale or overstated lines.
#[test]
fn stale_lines() {
    let test_sh = read("scripts/test.sh");
    let header: String = test_sh
        .lines()
        .take_while(|l| l.starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n");
    assert!(!header.contains("4. the link-time proof"), "{header}");
    assert!(
        !test_sh.contains("no-panic/check.sh\n"),
        "test.sh does not run the proof"
    );
    assert!(!read("host-sim/firmware/src/board.rs").contains("21 844"));
    for (name, text) in texts() {
        assert!(
            !text.contains("normal_of"),
            "{name} mentions a Mesh::normal_of"
        );
    }
    let readme = read("README.md");
    assert!(!readme.contains("feature is never removed."));
    assert!(readme.contains("never removed while it is one"));
    let fuzz_row = readme.lines().find(|l| l.contains("6 714 088")).unwrap();
    assert!(fuzz_row.contains("interrupted"), "{fuzz_row}");
}

/// Items 9 and 10: the README shows the workspace as a `static`, says what static_cell needs on
/// thumbv6m, and points at the runnable firmware example that scripts/test.sh runs.
#[test]
fn firmware_advice_and_example() {
    let readme = read("README.md");
    assert!(
        readme.contains("static WORKSPACE"),
        "the workspace as a static"
    );
    assert!(!readme.contains("let mut ws = Workspace::<u16, 512, 1024>::new();"));
    assert!(readme.contains("thumbv6m") && readme.contains("portable-atomic"));
    assert!(readme.contains("cortex_m::singleton!"));
    let cmd = "cargo run --release --example simplify_in_flash --target thumbv7em-none-eabihf";
    assert!(readme.contains(cmd));
    let example = read("examples/cortex-m4f/examples/simplify_in_flash.rs");
    assert!(example.contains("static POSITIONS") && example.contains("static WORKSPACE"));
    assert!(example.contains("defmt::info!"));
    let config = read("examples/cortex-m4f/.cargo/config.toml");
    assert!(config.contains("runner = \"./qemu-runner.sh\""));
    assert!(config.contains("# runner = \"probe-rs run"));
    let test_sh = read("scripts/test.sh");
    assert!(test_sh.contains("--example simplify_in_flash --target thumbv7em-none-eabihf"));
}

/// Item 13: the README names the cases the soft-float cores skip, as qemu.rs lists them.
#[test]
fn readme_names_the_expected_skips() {
    let readme = read("README.md");
    let qemu = read("host-sim/src/qemu.rs");
    for (list, board) in [("MICROBIT_SKIPS", "Cortex-M0"), ("LM3S_SKIPS", "Cortex-M3")] {
        let line = qemu
            .lines()
            .find(|l| l.starts_with(&format!("const {list}")))
            .unwrap();
        let para = &readme[readme.find(board).unwrap()..];
        let para = &para[..para.find(')').unwrap() + 200];
        for name in line.split('"').skip(1).step_by(2) {
            assert!(
                para.contains(&format!("`{name}`")),
                "{board} {name}: {para}"
            );
        }
    }
}

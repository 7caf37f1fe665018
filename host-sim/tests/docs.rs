//! The words of README.md, docs/, the scripts and the sources: citations and figures that were
//! wrong once must not come back; the README stays a short front door; every relative link in
//! the documentation resolves; and the published crate holds the library and nothing else.

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
            if p.ends_with("tests/fixtures") {
                // The meshes' provenance (SOURCES.md) quotes their sources' own words.
                continue;
            }
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

/// The progressive-mesh paper is Cheng, Pan and Shi's (not Hoppe's; his energy is cited as his
/// own), the bounded-error one Zhu, Wang and Meng's (not Garland-Heckbert's); the link
/// condition is Cheng, Pan and Shi §3.2(1).
#[test]
fn seed_citations() {
    let this = file!();
    for (name, text) in texts() {
        if name.ends_with(this.rsplit('/').next().unwrap()) {
            continue;
        }
        // The texture-stretch metric's paper has Hoppe among its authors; the energy cost
        // (`cost::Energy`) is Hoppe's own, cited by these three names only.
        let mut text = text.replace("Sander, Snyder, Gortler and Hoppe", "Sander et al.");
        for own in ["Hoppe's energy", "Hoppe et al. 1993", "Hoppe 1996"] {
            text = text.replace(own, "the energy");
        }
        for bad in [
            "Hoppe",
            "Garland-Heckbert",
            "Garland and Heckbert",
            "§3.1-3.3",
            // The passes and the normal variation W are the mobile paper's (Lin 2007).
            "Cheng, Pan and Shi's passes",
            "normal variation W (Cheng",
        ] {
            assert!(!text.contains(bad), "{name} still says {bad:?}");
        }
        for line in text.lines() {
            if line.contains("§3.1") {
                assert!(
                    line.contains("irregular") || line.contains("(§3.1)"),
                    "{name}: §3.1 of Cheng, Pan and Shi is the vertex classification: {line}"
                );
            }
        }
    }
    let legality = read("src/policy/legality.rs");
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

/// Stale or overstated lines.
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
    for (name, text) in texts() {
        assert!(
            !text.contains("feature is never removed."),
            "{name}: a feature is only kept while it is one"
        );
    }
    assert!(read("docs/algorithm.md").contains("never removed while it is one"));
    let fuzzing = read("docs/fuzzing.md");
    let fuzz_row = fuzzing.lines().find(|l| l.contains("6 714 088")).unwrap();
    assert!(fuzz_row.contains("interrupted"), "{fuzz_row}");
}

/// The README shows the workspace as a `static`, says what static_cell needs on
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

/// docs/devices.md names the cases the soft-float cores skip, as qemu.rs lists them.
#[test]
fn devices_doc_names_the_expected_skips() {
    let readme = read("docs/devices.md");
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

/// The README is a front door: short, and no log (dates, issue numbers, seed labels). The pages
/// of docs/ carry no dates or issue numbers either.
#[test]
fn readme_is_a_front_door() {
    let readme = read("README.md");
    let lines = readme.lines().count();
    assert!(lines <= 250, "README.md has {lines} lines (at most 250)");
    let mut pages = vec![("README.md".to_string(), readme)];
    for (name, text) in texts() {
        if name.contains("/docs/") && name.ends_with(".md") {
            pages.push((name, text));
        }
    }
    for (name, text) in &pages {
        for bad in ["2026", "seed 0", "this session", "this round"] {
            assert!(!text.contains(bad), "{name} says {bad:?}");
        }
        let lower = text.to_lowercase();
        for (i, _) in lower.match_indices("issue ") {
            let next = lower[i + 6..].chars().next();
            assert!(
                !next.is_some_and(|c| c.is_ascii_digit()),
                "{name} names an issue number: {}",
                &text[i..(i + 12).min(text.len())]
            );
        }
    }
    // The two commands a newcomer runs first, at the very top.
    let top: Vec<&str> = pages[0].1.lines().take(12).collect();
    assert!(
        top.contains(&"cargo run -p host-sim --release -- demo"),
        "{top:?}"
    );
    assert!(top.contains(&"scripts/test.sh"), "{top:?}");
    // Every Cargo feature of the library is explained.
    let manifest = read("Cargo.toml");
    let features = &manifest[manifest.find("[features]").unwrap()..];
    let features = &features[..features.find("\n[").unwrap()];
    for line in features.lines().skip(1) {
        if let Some((name, _)) = line.split_once(" = ") {
            if name != "default" && !name.starts_with('#') {
                assert!(pages[0].1.contains(&format!("`{name}`")), "feature {name}");
            }
        }
    }
}

/// GitHub's anchor for a heading: lower case, punctuation dropped, spaces as hyphens.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// Every relative link of README.md and docs/*.md names a file that exists, and a `#part` of a
/// Markdown file names one of its headings.
#[test]
fn documentation_links_resolve() {
    let mut pages = vec![root().join("README.md")];
    for e in std::fs::read_dir(root().join("docs")).unwrap().flatten() {
        if e.path().extension().is_some_and(|x| x == "md") {
            pages.push(e.path());
        }
    }
    let mut links = 0;
    for page in &pages {
        let text = std::fs::read_to_string(page).unwrap();
        let dir = page.parent().unwrap();
        for (i, _) in text.match_indices("](") {
            let rest = &text[i + 2..];
            let target = &rest[..rest.find(')').unwrap()];
            if target.starts_with("http") {
                continue;
            }
            links += 1;
            let (file, part) = target.split_once('#').unwrap_or((target, ""));
            let path = if file.is_empty() {
                page.clone()
            } else {
                dir.join(file)
            };
            assert!(path.exists(), "{}: no file {target}", page.display());
            if !part.is_empty() {
                let doc = std::fs::read_to_string(&path).unwrap();
                let found = doc
                    .lines()
                    .filter(|l| l.starts_with('#'))
                    .any(|l| anchor(l.trim_start_matches('#')) == part);
                assert!(found, "{}: no heading for {target}", page.display());
            }
        }
    }
    assert!(links > 30, "only {links} links checked");
}

/// `cargo package` ships the library, its README and both licences, and none of the harness,
/// fuzzing, tests, benchmarks or docs.
#[test]
fn the_package_holds_the_library_only() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args([
            "package",
            "--list",
            "--allow-dirty",
            "--no-verify",
            "-p",
            "tinydecimate",
        ])
        .current_dir(root())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let list = String::from_utf8(out.stdout).unwrap();
    let files: Vec<&str> = list.lines().collect();
    for needed in [
        "src/lib.rs",
        "src/workspace.rs",
        "Cargo.toml",
        "README.md",
        "LICENSE-MIT",
        "LICENSE-APACHE",
    ] {
        assert!(files.contains(&needed), "{needed} missing: {files:?}");
    }
    for f in &files {
        for dir in [
            "host-sim/",
            "fuzz/",
            "tests/",
            "bench/",
            "docs/",
            "examples/",
            "scripts/",
        ] {
            assert!(!f.starts_with(dir), "{f} is packaged");
        }
    }
    // The manifest's metadata is complete enough for crates.io.
    assert!(!stderr.contains("manifest has no"), "{stderr}");
}

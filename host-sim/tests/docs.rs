//! The words of README.md, docs/, the scripts and the sources: citations and figures that were
//! wrong once must not come back; the README stays a short front door; every relative link in
//! the documentation resolves; and the published crate holds the library and nothing else.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Every text file the citations and figures live in: README, docs, scripts and all `.rs`
/// files of the library, the tests, the command line and host-sim (firmware included).
fn texts() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut stack: Vec<PathBuf> = [
        "src",
        "tests",
        "cli/src",
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
    let legality = read("src/policy/legality/mod.rs");
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
    assert!(read("cli/src/metro.rs").contains("Zhu, Wang and Meng"));
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
    assert!(example.contains("cow::POSITIONS") && example.contains("static WORKSPACE"));
    let mesh = read("examples/cortex-m4f/src/cow.rs");
    assert!(
        mesh.contains("pub static POSITIONS"),
        "the mesh as a static, in flash"
    );
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
                // A row of its own in the features table.
                let row = format!("| `{name}` | ");
                assert!(
                    pages[0].1.lines().any(|l| l.starts_with(&row)),
                    "feature {name}"
                );
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

/// The two command lines whose reference pages are checked against their help.
#[derive(Clone, Copy, Debug)]
enum Binary {
    /// `tinydecimate` (cli/), documented in docs/cli.md.
    Cli,
    /// `host-sim`, documented in docs/harness.md.
    Harness,
}

impl Binary {
    fn page(self) -> &'static str {
        match self {
            Binary::Cli => "docs/cli.md",
            Binary::Harness => "docs/harness.md",
        }
    }
}

/// `BINARY ARGS --help` (long help), as text: host-sim's from the built binary, the command
/// line's from its parser (the binary belongs to another package).
fn help_of(bin: Binary, args: &[&str]) -> String {
    match bin {
        Binary::Harness => {
            let out = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"))
                .args(args)
                .arg("--help")
                .output()
                .unwrap();
            assert!(out.status.success(), "{args:?} --help failed");
            String::from_utf8(out.stdout).unwrap()
        }
        Binary::Cli => {
            use clap::CommandFactory;
            let argv = std::iter::once("tinydecimate")
                .chain(args.iter().copied())
                .chain(["--help"]);
            let e = match tinydecimate_cli::cmd::Cli::command().try_get_matches_from(argv) {
                Err(e) => e,
                Ok(_) => panic!("{args:?} --help parsed as a run"),
            };
            assert_eq!(e.kind(), clap::error::ErrorKind::DisplayHelp, "{args:?}");
            e.render().to_string()
        }
    }
}

/// What a command's `--help` lists: its subcommands, and its flags (long names, `--help` and
/// `--version` left out) each with its possible values.
#[derive(Debug, Default)]
struct Help {
    commands: Vec<String>,
    flags: Vec<(String, Vec<String>)>,
}

/// Reads clap's long help: `Commands:` lines (`  name  about`), option lines (`  -x, --flag
/// <V>` or `      --flag`), and under an option its values, as `[possible values: a, b]` or
/// a `Possible values:` list of `- a: ...` lines.
fn parse_help(text: &str) -> Help {
    let mut h = Help::default();
    let mut section = "";
    let mut in_values = false;
    for line in text.lines() {
        if !line.starts_with(' ') && line.ends_with(':') {
            section = line;
            in_values = false;
            continue;
        }
        let t = line.trim_start();
        let indent = line.len() - t.len();
        match section {
            "Commands:" if indent == 2 => {
                let name = t.split_whitespace().next().unwrap_or("");
                if name != "help" {
                    h.commands.push(name.to_string());
                }
            }
            "Options:" if indent <= 6 && t.starts_with('-') => {
                in_values = false;
                let long = t
                    .split([',', ' ', '='])
                    .find(|w| w.starts_with("--"))
                    .unwrap_or("");
                if !long.is_empty() && long != "--help" && long != "--version" {
                    // Short help puts the values on the option's line.
                    let values = t
                        .split_once("[possible values: ")
                        .map(|(_, l)| l.trim_end_matches(']').split(", ").map(str::to_string))
                        .map_or_else(Vec::new, Iterator::collect);
                    h.flags.push((long.to_string(), values));
                }
            }
            "Options:" => {
                let Some((_, values)) = h.flags.last_mut() else {
                    continue;
                };
                if let Some(list) = t.strip_prefix("[possible values: ") {
                    let list = list.trim_end_matches(']');
                    values.extend(list.split(", ").map(str::to_string));
                } else if t == "Possible values:" {
                    in_values = true;
                } else if in_values && t.starts_with("- ") {
                    let v = t[2..].split(':').next().unwrap_or("").trim();
                    values.push(v.to_string());
                } else if in_values && !t.is_empty() && indent <= 10 {
                    in_values = false;
                }
            }
            _ => {}
        }
    }
    h
}

/// Every leaf command (`simplify`, `pm encode`, ...) of `bin` and its help.
fn commands(bin: Binary) -> Vec<(String, Help)> {
    let top = parse_help(&help_of(bin, &[]));
    assert!(top.commands.len() >= 7, "{:?}", top.commands);
    let mut out = Vec::new();
    for c in top.commands {
        let h = parse_help(&help_of(bin, &[&c]));
        if h.commands.is_empty() {
            out.push((c, h));
        } else {
            for sub in &h.commands {
                out.push((format!("{c} {sub}"), parse_help(&help_of(bin, &[&c, sub]))));
            }
        }
    }
    out
}

/// The `--flags` a text names (`--flag`, `--flag=x`, `--flag <V>`).
fn flags_named(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let b = text.as_bytes();
    for (i, _) in text.match_indices("--") {
        let before = i.checked_sub(1).map(|j| b[j]);
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == b'-') {
            continue;
        }
        let name: String = text[i + 2..]
            .chars()
            .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '-')
            .collect();
        if name.len() > 1 && name.starts_with(|c: char| c.is_ascii_lowercase()) {
            out.push(format!("--{name}"));
        }
    }
    out
}

/// Whether `word` occurs in `text` bounded by characters that cannot be part of a name.
fn has_word(text: &str, word: &str) -> bool {
    let part = |c: char| c.is_ascii_alphanumeric() || c == '-' || c == '_';
    text.match_indices(word).any(|(i, _)| {
        !text[..i].chars().next_back().is_some_and(part)
            && !text[i + word.len()..].chars().next().is_some_and(part)
    })
}

/// A reference page's section of each command: `### `cmd`` up to the next heading.
fn reference(doc: &str, command: &str) -> Option<String> {
    let heading = format!("### `{command}`");
    let start = doc.lines().position(|l| l.trim_end() == heading)?;
    let body: Vec<&str> = doc
        .lines()
        .skip(start + 1)
        .take_while(|l| !l.starts_with('#'))
        .collect();
    Some(body.join("\n"))
}

/// docs/cli.md and docs/harness.md agree with `--help`: every command has a reference
/// section; every flag of a command's help is named there on a line that also names each of
/// its possible values; every flag the section names is in that command's help, and every
/// flag the page names is some command's.
#[test]
fn reference_pages_match_help() {
    let mut problems = Vec::new();
    for bin in [Binary::Cli, Binary::Harness] {
        problems.extend(reference_problems(bin));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// What [`reference_pages_match_help`] finds wrong in `bin`'s page.
fn reference_problems(bin: Binary) -> Vec<String> {
    let page = bin.page();
    let doc = read(page);
    let commands = commands(bin);
    let mut problems = Vec::new();
    for (name, help) in &commands {
        let Some(section) = reference(&doc, name) else {
            problems.push(format!("{page}: no section \"### `{name}`\""));
            continue;
        };
        for (flag, values) in &help.flags {
            let lines: Vec<&str> = section.lines().filter(|l| has_word(l, flag)).collect();
            if lines.is_empty() {
                problems.push(format!(
                    "{page}: {name}: {flag} is in --help, not in the docs"
                ));
            }
            for v in values {
                if !lines.iter().any(|l| has_word(l, v)) {
                    problems.push(format!(
                        "{page}: {name}: {flag} {v} is in --help, not in the docs"
                    ));
                }
            }
        }
        let known: Vec<&str> = help.flags.iter().map(|(f, _)| f.as_str()).collect();
        for flag in flags_named(&section) {
            if !known.contains(&flag.as_str()) {
                problems.push(format!(
                    "{page}: {name}: the docs name {flag}, --help has no such flag"
                ));
            }
        }
    }
    // Elsewhere on the page (the command table, cross-references): a flag some command has.
    let all: Vec<&str> = commands
        .iter()
        .flat_map(|(_, h)| h.flags.iter().map(|(f, _)| f.as_str()))
        .collect();
    // Cargo's and clap's own flags are no command's.
    let own = ["--release", "--help", "--version", "--path", "--features"];
    for flag in flags_named(&doc) {
        if !all.contains(&flag.as_str()) && !own.contains(&flag.as_str()) {
            problems.push(format!("{page} names {flag}, no command has it"));
        }
    }
    problems
}

/// The types the sources declare public, and every member name they declare (functions and
/// constants of any visibility, trait items, enum variants, public fields): from the library,
/// the command line and the shared checker.
fn declared_names() -> (BTreeSet<String>, BTreeSet<String>) {
    let (mut types, mut members) = (BTreeSet::new(), BTreeSet::new());
    let mut stack = vec![
        root().join("src"),
        root().join("cli/src"),
        root().join("meshcheck/src"),
    ];
    let kinds = [
        "fn", "struct", "enum", "trait", "const", "type", "mod", "static",
    ];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            let text = std::fs::read_to_string(&p).unwrap();
            let mut in_enum = false;
            for line in text.lines() {
                let t = line.trim_start();
                if t.starts_with("//") {
                    continue;
                }
                let words: Vec<&str> = t
                    .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                    .filter(|w| !w.is_empty())
                    .collect();
                // The item's keyword: the last of `pub const fn`, `pub(crate) unsafe fn`, ...
                let keyword = words.iter().position(|w| kinds.contains(w)).map(|i| {
                    let mut i = i;
                    while words.get(i + 1).is_some_and(|w| kinds.contains(w)) {
                        i += 1;
                    }
                    i
                });
                // Only visibility and qualifiers before it (not `what: &'static str`).
                let lead = [
                    "pub", "crate", "super", "const", "unsafe", "async", "extern",
                ];
                if let Some(i) = keyword.filter(|&i| words[..i].iter().all(|w| lead.contains(w))) {
                    if let Some(name) = words.get(i + 1) {
                        let public =
                            words.first() == Some(&"pub") && words.get(1) != Some(&"crate");
                        match words[i] {
                            "struct" | "enum" | "trait" | "type" if public => {
                                types.insert(name.to_string());
                            }
                            "struct" | "enum" | "trait" | "type" => {}
                            _ => {
                                members.insert(name.to_string());
                            }
                        }
                    }
                    in_enum = words[i] == "enum";
                } else if t.starts_with("pub ") && t.contains(':') {
                    if let Some(field) = words.get(1) {
                        members.insert(field.to_string());
                    }
                } else if words.first() == Some(&"pub") && words.get(1) == Some(&"use") {
                    // A re-export names its items here too.
                    for w in &words[2..] {
                        if w.starts_with(|c: char| c.is_ascii_uppercase()) {
                            types.insert(w.to_string());
                        }
                    }
                } else if in_enum && line.starts_with("    ") && !line.starts_with("     ") {
                    if let Some(v) = words.first().filter(|w| w.starts_with(char::is_uppercase)) {
                        members.insert(v.to_string());
                    }
                } else if line.starts_with('}') {
                    in_enum = false;
                }
            }
        }
    }
    (types, members)
}

/// The documentation names what exists: every Cargo feature it names is a feature of the
/// library, the command line or the harness, and every `Type::member` it names in backticks
/// for a public type of ours (a method, a constructor, a variant, an associated constant, a
/// field; `Type::{A, B}` names each) is declared.
#[test]
fn docs_name_features_and_items_that_exist() {
    let manifest_features = |path: &str| -> Vec<String> {
        let m = read(path);
        let f = &m[m.find("[features]").unwrap()..];
        let f = &f[..f[1..].find("\n[").map_or(f.len(), |i| i + 1)];
        f.lines()
            .skip(1)
            .filter_map(|l| l.split_once(" = ").map(|(n, _)| n.trim().to_string()))
            .filter(|n| !n.starts_with('#'))
            .collect()
    };
    let mut features = manifest_features("Cargo.toml");
    features.extend(manifest_features("cli/Cargo.toml"));
    features.extend(manifest_features("host-sim/Cargo.toml"));
    let (types, members) = declared_names();
    assert!(types.contains("Config") && members.contains("with_ratio"));
    let mut pages = vec![("README.md".to_string(), read("README.md"))];
    for (name, text) in texts() {
        if name.ends_with(".md") {
            pages.push((name, text));
        }
    }
    let mut problems = Vec::new();
    let mut checked = 0;
    for (name, text) in &pages {
        // `feature `x``, `features `x`, `y``, `--features x,y`.
        for (i, _) in text.match_indices("feature") {
            let rest = &text[i..];
            let rest = rest
                .strip_prefix("features")
                .or_else(|| rest.strip_prefix("feature"))
                .unwrap();
            let named: Vec<&str> = if let Some(r) = rest.strip_prefix(" `") {
                let mut out = vec![r.split('`').next().unwrap_or("")];
                // A list: `a`, `b` and `c`.
                let mut r = &r[out[0].len() + 1..];
                while let Some(next) = r
                    .strip_prefix(", `")
                    .or_else(|| r.strip_prefix(" and `"))
                    .or_else(|| r.strip_prefix(", and `"))
                {
                    let n = next.split('`').next().unwrap_or("");
                    out.push(n);
                    r = &next[n.len() + 1..];
                }
                out
            } else if let Some(r) = rest.strip_prefix(" ") {
                if text[..i].ends_with("--") {
                    r.split(|c: char| c.is_whitespace() || c == '`' || c == ')')
                        .next()
                        .unwrap_or("")
                        .split(',')
                        .collect()
                } else {
                    Vec::new()
                }
            } else {
                Vec::new()
            };
            for n in named {
                let n = n.trim_matches('"');
                if n.is_empty() || !n.chars().all(|c| c.is_ascii_lowercase() || c == '_') {
                    continue;
                }
                checked += 1;
                if !features.iter().any(|f| f == n) {
                    problems.push(format!(
                        "{name}: names Cargo feature `{n}`, which no manifest has"
                    ));
                }
            }
        }
        // `Type::member` in backticks, for a Type of ours.
        for span in text.split('`').skip(1).step_by(2) {
            let path = span.split(['(', '<', ' ']).next().unwrap_or("");
            let parts: Vec<&str> = path.split("::").collect();
            if parts.len() < 2 {
                continue;
            }
            let ty = parts[parts.len() - 2];
            if !types.contains(ty) {
                continue;
            }
            // `Type::member`, or a group `Type::{A, B}` (the whole span after the type).
            let tail = span.rsplit_once(&format!("{ty}::")).map_or("", |(_, t)| t);
            let named: Vec<&str> = match tail.strip_prefix('{') {
                Some(group) => group
                    .trim_end_matches('}')
                    .split(',')
                    .map(str::trim)
                    .collect(),
                None => vec![parts[parts.len() - 1]],
            };
            for member in named.into_iter().filter(|m| !m.is_empty()) {
                checked += 1;
                if !members.contains(member) && !types.contains(member) {
                    problems.push(format!("{name}: `{span}`: {ty} declares no {member}"));
                }
            }
        }
    }
    assert!(checked > 100, "only {checked} names checked");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The README's modes table quotes each mode's time against meshoptimizer from the bench's
/// generated results (bench/results.json, `host-sim bench`), rounded as printed: a re-run of
/// the bench that changes a figure fails here until the README says the new one.
#[test]
fn readme_times_are_the_bench_results() {
    let results: serde_json::Value = serde_json::from_str(&read("bench/results.json")).unwrap();
    let geomean = |method: &str| -> f64 {
        results["summary"]["modes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["method"] == method)
            .and_then(|m| m["time_vs_meshopt_geomean"].as_f64())
            .unwrap_or_else(|| panic!("no {method} in bench/results.json"))
    };
    let rows = [
        ("memoryless quadric, greedy", "default"),
        ("memoryless quadric in meshoptimizer's passes", "batched"),
        ("the paper's normal variation W, its passes", "paper"),
        ("normal variation W, greedy", "greedy_w"),
        ("stored quadrics, subset placement", "stored"),
        ("stored quadrics, optimal placement", "stored_optimal"),
        ("vertex decimation", "vertex_decimation"),
        ("Hoppe's energy as the cost", "energy"),
    ];
    let readme = read("README.md");
    let mut problems = Vec::new();
    for (label, method) in rows {
        let row = readme
            .lines()
            .find(|l| l.starts_with(&format!("| {label}")))
            .unwrap_or_else(|| panic!("README has no modes row {label:?}"));
        // The speed column: the fifth cell; its first `N.NNx` is the time.
        let speed = row.split('|').nth(5).unwrap_or("");
        let quoted = speed
            .split_whitespace()
            .find_map(|w| w.strip_suffix('x').and_then(|n| n.parse::<f64>().ok()));
        let want = format!("{:.2}", geomean(method));
        match quoted {
            Some(q) if format!("{q:.2}") == want => {}
            other => problems.push(format!(
                "{label}: README says {other:?}x, the bench {want}x"
            )),
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The README's instructions per collapse on the M4F and its flash of one instantiation per
/// target are the rows of bench/DEVICES.md (written by `host-sim qemu --measure --out
/// bench/DEVICES.md`).
#[test]
fn readme_instructions_are_the_device_tables() {
    let tables = read("bench/DEVICES.md");
    // Cell `column` of the row that starts with the cells `first`.
    let cell = |first: &str, column: usize| -> String {
        let row = tables
            .lines()
            .find(|l| l.starts_with(&format!("| {first} |")))
            .unwrap_or_else(|| panic!("bench/DEVICES.md has no row | {first} |"));
        row.split('|').nth(column).unwrap().trim().to_string()
    };
    // The boards table's "1-inst flash" column, per board.
    let flash = |board: &str| cell(board, 5);
    let said = format!(
        "**{}** on thumbv7em, **{}** on thumbv6m, **{}** on riscv32imc",
        flash("mps2-an386") + " B",
        flash("microbit") + " B",
        flash("riscv32imc-virt-400k") + " B"
    );
    assert!(
        read("README.md").contains(&said),
        "README does not say {said:?}"
    );
    // The cases table's "per collapse" column on the M4F.
    let per_collapse = |case: &str| cell(&format!("mps2-an386 | {case}"), 6);
    let (exact, fast) = (per_collapse("cow-new-u16"), per_collapse("cow-fast-u16"));
    let readme = read("README.md");
    let said = format!("{exact} emulated instructions on the M4F for the cow ({fast} in the");
    assert!(
        readme.replace('\n', " ").contains(&said),
        "README does not say {said:?}"
    );
}

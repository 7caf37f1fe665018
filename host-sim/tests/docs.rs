//! The words of README.md, docs/, the scripts and the sources: citations and figures that were
//! wrong once must not come back; the README stays a short front door; every relative link in
//! the documentation resolves; and the published crate holds the library and nothing else.

use host_sim::qemu::measure::spaced;
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

/// docs/devices.md's "Expected skips" paragraph names exactly the cases the Cortex-M0 and
/// Cortex-M3 boards skip (`EXPECTED_SKIPS`): the cases both skip, then "The Cortex-M0 also
/// skips" and its own.
#[test]
fn devices_doc_names_the_expected_skips() {
    let skips = |board: &str| -> BTreeSet<String> {
        let (_, cases) = host_sim::qemu::EXPECTED_SKIPS
            .iter()
            .find(|(b, _)| *b == board)
            .unwrap_or_else(|| panic!("no {board} in EXPECTED_SKIPS"));
        cases.iter().map(|c| c.to_string()).collect()
    };
    let (m0, m3) = (skips("microbit"), skips("lm3s6965evb"));
    assert!(m0.len() > 20 && m3.len() > 20, "{m0:?} {m3:?}");
    assert!(
        m3.is_subset(&m0),
        "the Cortex-M3 skips a case the M0 runs: the page says it does not"
    );
    // Case names in backticks: lower case, digits and hyphens.
    let named = |text: &str| -> BTreeSet<String> {
        text.split('`')
            .skip(1)
            .step_by(2)
            .filter(|w| {
                w.contains('-')
                    && w.chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
            })
            .map(str::to_string)
            .collect()
    };
    let page = read("docs/devices.md");
    let start = page
        .find("**Expected skips.**")
        .expect("an Expected skips paragraph");
    let para = &page[start..];
    let para = &para[..para.find("\n\n").unwrap_or(para.len())];
    let (both, own) = para
        .split_once("The Cortex-M0 also skips")
        .expect("the M0's own skips");
    let own = &own[..own.find(". ").unwrap_or(own.len())];
    assert_eq!(named(both), &m0 & &m3, "the cases both boards skip");
    assert_eq!(named(own), &m0 - &m3, "the cases only the Cortex-M0 skips");
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

/// The summary of one mode (`"default"`, `"batched"`, `"meshopt"`, ...) in bench/results.json.
fn bench_mode(method: &str) -> serde_json::Value {
    let results: serde_json::Value = serde_json::from_str(&read("bench/results.json")).unwrap();
    results["summary"]["modes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["method"] == method)
        .unwrap_or_else(|| panic!("no {method} in bench/results.json"))
        .clone()
}

/// The README's modes table quotes each mode's time against meshoptimizer from the bench's
/// generated results (bench/results.json, `host-sim bench`), rounded as printed: a re-run of
/// the bench that changes a figure fails here until the README says the new one.
#[test]
fn readme_times_are_the_bench_results() {
    let geomean = |method: &str| -> f64 {
        bench_mode(method)["time_vs_meshopt_geomean"]
            .as_f64()
            .unwrap_or_else(|| panic!("{method}: no time in bench/results.json"))
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

/// The measured figures of a Markdown text outside code: a ratio (`0.55x`; `1.0x`, a target, is
/// not one), an instruction count (`29.7 k`, `85.3 M`, `2 612 instructions`), a byte count of a
/// thousand or more (`22 328 B`), a time (`0.54 ms`, `3 s`) and an error with decimals
/// (`0.72 %`; `10 %`, a target, is not one).
fn measured_figures(text: &str) -> Vec<String> {
    // Drop fenced blocks and inline code: commands and code, not prose.
    let mut prose = String::new();
    for (i, block) in text.split("```").enumerate() {
        if i % 2 == 0 {
            for (j, part) in block.split('`').enumerate() {
                if j % 2 == 0 {
                    prose.push_str(part);
                }
                prose.push(' ');
            }
        }
    }
    let chars: Vec<char> = prose.chars().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts = chars[i].is_ascii_digit()
            && (i == 0
                || !(chars[i - 1].is_alphanumeric() || matches!(chars[i - 1], '.' | '-' | '_')));
        if !starts {
            i += 1;
            continue;
        }
        // The number: digits, thousands groups after a space, a fraction.
        let mut end = i;
        while end < chars.len() && chars[end].is_ascii_digit() {
            end += 1;
        }
        while end + 3 < chars.len()
            && chars[end] == ' '
            && chars[end + 1..end + 4].iter().all(char::is_ascii_digit)
            && chars.get(end + 4).is_none_or(|c| !c.is_ascii_digit())
        {
            end += 4;
        }
        if end + 1 < chars.len() && chars[end] == '.' && chars[end + 1].is_ascii_digit() {
            end += 1;
            while end < chars.len() && chars[end].is_ascii_digit() {
                end += 1;
            }
        }
        let number: String = chars[i..end].iter().collect();
        let rest: String = chars[end..(end + 14).min(chars.len())].iter().collect();
        let value: f64 = number.replace(' ', "").parse().unwrap_or(0.0);
        let unit = |u: &str| {
            [u.to_string(), format!(" {u}")].iter().any(|w| {
                rest.starts_with(w.as_str())
                    && rest[w.len()..]
                        .chars()
                        .next()
                        .is_none_or(|c| !c.is_alphanumeric())
            })
        };
        let figure = (unit("x") && value != 1.0)
            || unit("k")
            || unit("M")
            || rest.starts_with(" instructions")
            || (unit("B") && value >= 1000.0)
            || unit("ms")
            || unit("s")
            || (number.contains('.') && unit("%"));
        if figure {
            let unit: String = rest
                .trim_start()
                .chars()
                .take_while(|c| c.is_alphabetic())
                .collect();
            found.push(format!("{number}{unit}"));
        }
        i = end;
    }
    found
}

/// The pages of docs/ link to the generated tables (bench/DEVICES.md, bench/FLASH.md,
/// bench/RESULTS.md, bench/STORED.md, bench/CLUSTER.md) and quote no measurement themselves:
/// what was tried and dropped is a decision record that points at git history for its figures.
/// The README's few figures are checked cell by cell (`readme_figures_are_the_generated_tables`).
#[test]
fn figure_pages_quote_no_measurement() {
    let planted = "took 29.7 k instructions (0.55x), 22 328 B and 0.54 ms for 0.72 % at 10 %; \
                   1.0x is a target, 16 KB a board, `85.3 M` code";
    assert_eq!(
        measured_figures(planted),
        ["29.7k", "0.55x", "22 328B", "0.54ms", "0.72"],
        "the figure scanner"
    );
    let mut problems = Vec::new();
    let mut pages = 0;
    for (page, text) in texts() {
        if !(page.contains("/docs/") && page.ends_with(".md")) {
            continue;
        }
        pages += 1;
        let figures = measured_figures(&text);
        if !figures.is_empty() {
            problems.push(format!("{page} quotes {figures:?}"));
        }
    }
    assert!(pages >= 15, "only {pages} pages of docs/ read");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Cell `column` (a header's text) of the row of the generated table `file` whose first cells
/// are `first` (`"board | case"`), with bold marks dropped.
fn table_cell(file: &str, first: &str, column: &str) -> String {
    let text = read(file);
    let lines: Vec<&str> = text.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with(&format!("| {first} |")))
        .unwrap_or_else(|| panic!("{file} has no row | {first} |"));
    // The table's header is the line above its `|---` separator.
    let separator = (0..at)
        .rev()
        .find(|&i| lines[i].starts_with("|---"))
        .unwrap_or_else(|| panic!("{file}: row {first:?} has no header"));
    let header: Vec<&str> = lines[separator - 1].split('|').map(str::trim).collect();
    let index = header
        .iter()
        .position(|h| *h == column)
        .unwrap_or_else(|| panic!("{file}: no column {column:?} in {header:?}"));
    let cell = lines[at].split('|').nth(index).unwrap_or("");
    cell.replace("**", "").trim().to_string()
}

/// A cell's number: its digits before any unit or parenthesis (`"**22 328 B** (21.8 KB)"` and
/// `"+2 220 B"` give 22 328 and 2 220).
fn number(cell: &str) -> u64 {
    let digits: String = cell
        .trim_start_matches('+')
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == ' ')
        .filter(char::is_ascii_digit)
        .collect();
    digits
        .parse()
        .unwrap_or_else(|_| panic!("no number in {cell:?}"))
}

/// Every figure of the README's "firmware engineer's numbers" and of its modes table that is a
/// measurement is a cell of a generated file: bench/FLASH.md (`scripts/flash.sh --all --out
/// bench/FLASH.md`), bench/DEVICES.md (`host-sim qemu --measure --out bench/DEVICES.md`),
/// bench/results.json and bench/CLUSTER.md (`host-sim bench`). A re-measure that changes one
/// fails here until the README says the new figure.
#[test]
fn readme_figures_are_the_generated_tables() {
    let readme = read("README.md").replace('\n', " ");
    let mut problems = Vec::new();
    let mut says = |what: String| {
        if !readme.contains(&what) {
            problems.push(format!("README does not say {what:?}"));
        }
    };

    // Flash, bench/FLASH.md; the default call's agrees with bench/DEVICES.md's boards.
    let default = "Workspace<u16, 512, 1024>::simplify, u16 triangles, Config::new()";
    let flash = |target: &str, variant: &str, column: &str| {
        number(&table_cell(
            "bench/FLASH.md",
            &format!("{target} | {variant}"),
            column,
        ))
    };
    let library = |target: &str, variant: &str| flash(target, variant, "library (difference)");
    let added = |variant: &str| flash("thumbv7em-none-eabihf", variant, "over the default call");
    let (v7em, v6m, rv) = (
        library("thumbv7em-none-eabihf", default),
        library("thumbv6m-none-eabi", default),
        library("riscv32imc-unknown-none-elf", default),
    );
    says(format!(
        "**{} B** on thumbv7em, **{} B** on thumbv6m, **{} B** on riscv32imc",
        spaced(v7em),
        spaced(v6m),
        spaced(rv)
    ));
    for (board, bytes) in [
        ("mps2-an386", v7em),
        ("microbit", v6m),
        ("riscv32imc-virt-400k", rv),
    ] {
        let measured = number(&table_cell("bench/DEVICES.md", board, "1-inst flash"));
        assert_eq!(
            measured, bytes,
            "{board}: bench/DEVICES.md and bench/FLASH.md"
        );
    }
    let second = "Config::new(), Workspace<u16, 512, 1024>: u16 triangles + u32 triangles";
    says(format!(
        "a second index type in the same firmware adds {} B on thumbv7em",
        spaced(added(second))
    ));
    for feature in ["batched", "seams", "parts"] {
        let variant =
            format!("Workspace<u16, 512, 1024>::simplify, Config::new(), feature {feature}");
        says(format!(
            "| +{} B with the feature |",
            spaced(added(&variant))
        ));
    }
    let fast = "fast mode: FastWorkspace<u16, 512, 1024>::simplify, u16 triangles, Config::new()";
    let lean = "lean mode: LeanWorkspace<u16, 512, 1024>::simplify, u16 triangles, Config::new()";
    says(format!(
        "| {} B ([bench/FLASH.md](bench/FLASH.md)) |",
        spaced(library("thumbv7em-none-eabihf", fast))
    ));
    says(format!(
        "| {} B (same file) |",
        spaced(library("thumbv7em-none-eabihf", lean))
    ));

    // Stack and instructions, bench/DEVICES.md.
    let case = |case: &str, column: &str| {
        number(&table_cell(
            "bench/DEVICES.md",
            &format!("mps2-an386 | {case}"),
            column,
        ))
    };
    let board_stack = |board: &str| number(&table_cell("bench/DEVICES.md", board, "library stack"));
    says(format!(
        "{} B on the M4F, {} B on the M0, {} B with vertex decimation",
        spaced(case("cow-new-u16", "library stack")),
        spaced(board_stack("microbit")),
        spaced(board_stack("mps2-an386"))
    ));
    let (exact, fast) = (
        case("cow-new-u16", "per collapse"),
        case("cow-fast-u16", "per collapse"),
    );
    says(format!(
        "{} emulated instructions on the M4F for the cow ({} in the fast mode), about {:.2} ms ({:.2} ms) at 64 MHz",
        spaced(exact),
        spaced(fast),
        exact as f64 / 64e3,
        fast as f64 / 64e3
    ));
    // The M4F's cases, for the ranges of a kind of case.
    let devices = read("bench/DEVICES.md");
    let cases: Vec<(String, u64, u64)> = devices
        .lines()
        .filter_map(|l| l.strip_prefix("| mps2-an386 | "))
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            // The cases table's rows: case | triangles in → out | collapses | instructions |
            // per collapse | library stack.
            (cells.len() >= 6 && cells[1].contains('→'))
                .then(|| (cells[0].to_string(), number(cells[4]), number(cells[5])))
        })
        .collect();
    let deepest = cases.iter().max_by_key(|c| c.2).unwrap();
    assert!(
        deepest.0.contains("decimation"),
        "the deepest stack on the M4F is {deepest:?}, not vertex decimation's"
    );
    let range = |kind: &str| {
        let per: Vec<u64> = cases
            .iter()
            .filter(|c| c.0.contains(kind))
            .map(|c| c.1)
            .collect();
        assert!(per.len() >= 2, "{kind}: {per:?}");
        let (lo, hi) = (per.iter().min().unwrap(), per.iter().max().unwrap());
        format!(
            "{} – {} instructions per collapse on the M4F",
            spaced(*lo),
            spaced(*hi)
        )
    };
    says(range("-stored-optimal-"));
    says(range("-bound"));
    says(range("-envelope"));
    let stream = |column: &str| {
        number(&table_cell(
            "bench/DEVICES.md",
            "mps2-an386 | pm-cow-quantised",
            column,
        ))
    };
    says(format!(
        "{} instructions per collapse, {} per split on the M4F's slider",
        spaced(stream("coarsen")),
        spaced(stream("refine"))
    ));

    // Error and memory against meshoptimizer, bench/results.json.
    let mean = |method: &str| {
        bench_mode(method)["overall"]["mean_geomean"]
            .as_f64()
            .unwrap()
    };
    let scratch = bench_mode("meshopt")["scratch_bytes_per_triangle"].clone();
    says(format!(
        "meshoptimizer takes {:.1}-{:.1} B on the bench meshes",
        scratch[0].as_f64().unwrap(),
        scratch[1].as_f64().unwrap()
    ));
    says(format!(
        "Metro mean error {:.2}x meshoptimizer's (geometric mean; the default's {:.2}x)",
        mean("batched"),
        mean("default")
    ));
    says(format!(
        "Metro mean error {:.2}x meshoptimizer's (geometric mean) |",
        mean("energy")
    ));
    let worst: Vec<String> = bench_mode("vertex_decimation")["worst"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| format!("{:.2}x", w["clean"]["mean_vs_meshopt"].as_f64().unwrap()))
        .collect();
    says(format!(
        "worst mean error on the clean meshes {} meshoptimizer's at 50 / 25 / 10 %",
        worst.join(" / ")
    ));

    // Clustering against simplifySloppy, bench/CLUSTER.md's summary sentences.
    let cluster = read("bench/CLUSTER.md");
    let geomean = |words: &str| -> String {
        let sentence = cluster
            .split(". ")
            .find(|s| s.contains(words))
            .unwrap_or_else(|| panic!("bench/CLUSTER.md says nothing of {words:?}"));
        let at = sentence.find("geometric mean ").unwrap() + "geometric mean ".len();
        let word = sentence[at..].split(' ').next().unwrap();
        word.trim_end_matches(['.', ',', ';']).to_string()
    };
    says(format!(
        "{} `simplifySloppy`'s time with 40 B per vertex, {} streamed",
        geomean("40 B per input vertex"),
        geomean("memory for the output only")
    ));
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

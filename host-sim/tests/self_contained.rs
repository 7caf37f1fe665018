//! A clone is self-contained: no tracked file names a path outside the repository (a sibling
//! folder such as `../shared`, or an absolute path on one machine), and every mesh the
//! tests, goldens and bench read is in `tests/fixtures` or `bench/meshes` with its source in
//! the folder's SOURCES.md.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every text file of the repository, build outputs and git's own files left out.
fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name == ".git" || name.starts_with("target") || name == "corpus" {
            continue;
        }
        if p.is_dir() {
            text_files(&p, out);
        } else if let Ok(s) = std::fs::read(&p) {
            if !s.contains(&0) {
                out.push(p);
            }
        }
    }
}

#[test]
fn no_file_names_a_path_outside_the_repository() {
    let mut files = Vec::new();
    text_files(&root(), &mut files);
    assert!(files.len() > 100, "{} files", files.len());
    // Spelled in two pieces so that this file does not name them itself.
    let (sibling, absolute) = (concat!("..", "/shared/"), concat!("/wo", "rk/"));
    let mut bad = Vec::new();
    for f in &files {
        let s = String::from_utf8_lossy(&std::fs::read(f).unwrap()).into_owned();
        for (i, line) in s.lines().enumerate() {
            if line.contains(sibling) || line.contains(absolute) {
                bad.push(format!("{}:{}: {}", f.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "paths outside the repository:\n{}",
        bad.join("\n")
    );
}

#[test]
fn every_fixture_mesh_has_its_source() {
    // The tests' meshes, and the bench's own (too large for the fixtures the tests walk).
    for (folder, least) in [("tests/fixtures", 13), ("bench/meshes", 1)] {
        let dir = root().join(folder);
        let sources = std::fs::read_to_string(dir.join("SOURCES.md")).unwrap();
        let mut meshes = 0;
        for e in std::fs::read_dir(&dir).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            if name.ends_with(".obj") || name.ends_with(".glb") {
                meshes += 1;
                assert!(
                    sources.contains(&format!("`{name}`")),
                    "{name} is not in {folder}/SOURCES.md"
                );
            }
        }
        assert!(meshes >= least, "{folder}: {meshes} meshes");
    }
}

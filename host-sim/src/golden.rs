//! Golden results: the exact output of every case in `tests/golden/cases.toml`, per math
//! backend, checked on the host (`host-sim golden --check`) and on every emulated board
//! (`host-sim qemu --check`).
//!
//! Layout of `tests/golden/`:
//!
//! * `cases.toml`: the cases, written by hand. Each names a mesh (a generator of
//!   [`meshfmt::golden`], e.g. `grid 12`, or a file under `tests/`, optionally cut to a box and
//!   with extra positions/triangles appended), the configuration (`Config::new()` or
//!   `Config::paper()` with schedule, ratio, target, λ and feature mode spelled out) and the
//!   index type of the triangles.
//! * `<backend>/<case>.bin`: the expected output triangles, exactly as the library leaves them
//!   in the caller's buffer: `triangles_out × 3` indices of the case's index type,
//!   little-endian (the bytes the firmware writes after its result header).
//! * `<backend>/<case>.txt`: readable and TOML: the case, the hash of its input, every count of
//!   the library's report and the SHA-256 of the `.bin`. Regenerated from a run and compared as
//!   text, so any change in a count shows as a changed line.
//!
//! `<backend>` is `libm` or `micromath`, the library's two math backends (a compile-time
//! feature: host-sim's `micromath` feature forwards to `tinydecimate/micromath`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

pub mod case;
pub mod cluster;
pub mod files;
pub mod stream;

pub use case::{load_cases, load_mesh, load_specs, reference, Case, CaseSpec, Outcome};
pub use files::{diff, judge, sha256_hex, text_diff, triangle_bytes, Golden, Verdict};

use crate::backend::Backend;
use crate::repo_root;

/// The case list inside the golden directory.
pub const MANIFEST: &str = "cases.toml";

/// The golden directory: `tests/golden`.
pub fn default_dir() -> PathBuf {
    repo_root().join("tests").join("golden")
}

/// Runs every case of `dir/cases.toml` on the host and compares with `dir/<backend>/`. The
/// backend must be the one this binary was built with.
pub fn check_host(dir: &Path, backend: Backend) -> Result<Vec<(Case, Verdict)>> {
    if backend != Backend::compiled() {
        bail!(
            "this host-sim runs the library with {}, not {backend}",
            Backend::compiled()
        );
    }
    let mut out = Vec::new();
    for case in load_cases(dir)? {
        let now = reference(&case)?;
        let v = match Golden::load(dir, backend, &case.name)? {
            Some(g) => judge(&case, backend, &g, &now)?,
            None => Verdict::Failed(format!(
                "no golden files {}/{}/{}.txt|.bin (run `host-sim golden --bless --backend {backend}`)",
                dir.display(),
                backend,
                case.name
            )),
        };
        out.push((case, v));
    }
    Ok(out)
}

/// Recomputes every case on the host and writes `dir/<backend>/`; removes the files of cases
/// no longer in the manifest. Returns one line per case saying what changed.
pub fn bless(dir: &Path, backend: Backend) -> Result<Vec<String>> {
    if backend != Backend::compiled() {
        bail!(
            "this host-sim runs the library with {}, not {backend}",
            Backend::compiled()
        );
    }
    let cases = load_cases(dir)?;
    let streams = case::load_stream_specs(dir)?;
    // The clustering cases (`cluster.toml`, `host-sim qemu --cluster`) share the directories.
    let clusters = cluster::load_specs(dir)?;
    let mut lines = Vec::new();
    for case in &cases {
        let new = Golden::from_outcome(case, backend, &reference(case)?)?;
        let line = match Golden::load(dir, backend, &case.name)? {
            None => format!("{:<28} new      {}", case.name, new.summary()),
            Some(old) if old == new => format!("{:<28} same     {}", case.name, new.summary()),
            Some(old) => {
                let mut s = format!(
                    "{:<28} CHANGED  old {}\n{:<37}new {}",
                    case.name,
                    old.summary(),
                    "",
                    new.summary()
                );
                if let Verdict::Diff(d) = diff(case.index_type, &old, &new) {
                    for l in d {
                        let _ = write!(s, "\n{:<37}{l}", "");
                    }
                }
                s
            }
        };
        new.save(dir, backend, &case.name)?;
        lines.push(line);
    }
    let sub = dir.join(backend.name());
    let mut stale: Vec<_> = std::fs::read_dir(&sub)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or("");
            let ext = p.extension().and_then(|s| s.to_str()).unwrap_or("");
            (ext == "txt" || ext == "bin")
                && !cases.iter().any(|c| c.name == stem)
                && !streams.iter().any(|c| c.name == stem)
                && !clusters.iter().any(|c| c.name == stem)
        })
        .collect();
    stale.sort();
    for p in stale {
        std::fs::remove_file(&p)?;
        lines.push(format!("removed {} (not in {MANIFEST})", p.display()));
    }
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use case::{Base, Features, IndexName, ScheduleName};
    use meshfmt::{Board, Status};
    use tinydecimate::Config;

    /// `host-sim golden --check` on the host, for the backend this test binary was built with
    /// (`cargo test -p host-sim [--features micromath]`).
    #[test]
    fn golden_check_passes_on_the_host() {
        let results = check_host(&default_dir(), Backend::compiled()).unwrap();
        let bad: Vec<_> = results
            .iter()
            .filter(|(_, v)| *v != Verdict::Identical)
            .map(|(c, v)| format!("{}: {v:?}", c.name))
            .collect();
        assert!(
            bad.is_empty(),
            "golden mismatch ({}):\n{}",
            Backend::compiled(),
            bad.join("\n")
        );
    }

    /// The backend switch is real: the two backends' goldens exist for every case, and differ.
    #[test]
    fn libm_and_micromath_goldens_differ() {
        let dir = default_dir();
        let mut differ = Vec::new();
        for spec in load_specs(&dir).unwrap() {
            let l = Golden::load(&dir, Backend::Libm, &spec.name).unwrap();
            let m = Golden::load(&dir, Backend::Micromath, &spec.name).unwrap();
            let (l, m) = (l.expect("libm golden"), m.expect("micromath golden"));
            if l.bin != m.bin {
                differ.push(spec.name);
            }
        }
        assert!(
            !differ.is_empty(),
            "libm and micromath give the same bytes in every case"
        );
    }

    /// The cases cover what the goldens promise, and the micro:bit-sized ones fit it.
    #[test]
    fn manifest_covers_the_required_cases() {
        let specs = load_specs(&default_dir()).unwrap();
        let cases: Vec<_> = specs.iter().map(|s| Case::from_spec(s).unwrap()).collect();
        let has =
            |f: &dyn Fn(&CaseSpec, &Case) -> bool| specs.iter().zip(&cases).any(|(s, c)| f(s, c));
        assert!(has(
            &|s, _| s.config == Base::New && s.config() == Config::new().with_ratio(s.ratio)
        ));
        assert!(has(
            &|s, _| s.config == Base::Paper && s.config() == Config::paper().with_ratio(s.ratio)
        ));
        assert!(has(&|s, _| s.schedule == ScheduleName::Greedy));
        assert!(has(&|s, _| s.schedule == ScheduleName::Passes));
        assert!(has(&|s, _| s.index == IndexName::U16));
        assert!(has(&|s, _| s.index == IndexName::U32));
        assert!(has(&|s, _| s.features == Features::Valence));
        assert!(has(&|s, _| s.features == Features::Off));
        assert!(has(&|s, _| s.target_triangles > 0));
        // Edge use counts: open (an edge with one triangle), non-manifold (three).
        let edge_uses = |c: &Case| {
            let mut e = std::collections::HashMap::new();
            for t in &c.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    if a != b {
                        *e.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
                    }
                }
            }
            e
        };
        assert!(
            has(&|_, c| edge_uses(c).values().any(|&n| n == 1)),
            "open mesh"
        );
        assert!(
            has(&|_, c| edge_uses(c).values().all(|&n| n == 2)),
            "closed mesh"
        );
        assert!(
            has(&|_, c| edge_uses(c).values().any(|&n| n >= 3)),
            "non-manifold edge"
        );
        assert!(
            has(&|s, _| s.mesh.starts_with("tests/fixtures/plate_holes") && s.cut.is_some()),
            "CAD cut"
        );
        assert!(
            has(&|_, c| c
                .triangles
                .iter()
                .any(|t| t[0] == t[1] || t[1] == t[2] || t[0] == t[2])),
            "degenerate"
        );
        // Micro:bit: 240 vertices, 440 u16 / 220 u32 triangles.
        let fits = |c: &Case| {
            c.positions.len() <= 240 && c.triangles.len() * c.index_type.triangle_bytes() <= 440 * 6
        };
        assert!(cases.iter().filter(|c| fits(c)).count() >= 12);
        assert!(cases.iter().any(|c| !fits(c)), "a case the micro:bit skips");
    }

    /// Every case of the pipeline in integers has its float case (`Case::float_twin`), which
    /// `qemu --measure` puts it beside: the same mesh, triangles, target, index type and mode;
    /// its positions are grid coordinates, exact in the case file's `f32`.
    #[test]
    fn integer_cases_stand_beside_their_float_case() {
        let cases = load_cases(&default_dir()).unwrap();
        let integer: Vec<&Case> = cases.iter().filter(|c| c.float_twin().is_some()).collect();
        assert!(integer.len() >= 10, "{} integer cases", integer.len());
        for c in integer {
            let twin = c.float_twin().unwrap();
            let f = cases
                .iter()
                .find(|f| f.name == twin)
                .unwrap_or_else(|| panic!("{}: no float case {twin}", c.name));
            let (fm, cm) = (f.method.unwrap(), c.method.unwrap());
            assert!(!fm.integer() && cm.integer(), "{}", c.name);
            assert!(fm.pipeline().is_some(), "{}", c.name);
            assert_eq!(fm.pipeline(), cm.pipeline(), "{}", c.name);
            assert_eq!(f.wedges.len(), 0, "{}", c.name);
            assert_eq!(
                (f.index_type, f.config, &f.triangles, f.positions.len()),
                (c.index_type, c.config, &c.triangles, c.positions.len()),
                "{}",
                c.name
            );
            assert!(
                c.positions
                    .iter()
                    .flatten()
                    .all(|&x| x.fract() == 0.0 && (0.0..32_768.0).contains(&x)),
                "{}: positions off the grid",
                c.name
            );
        }
    }

    #[test]
    fn cases_round_trip_through_the_case_file() {
        for c in load_cases(&default_dir()).unwrap() {
            let bytes = c.encode().unwrap();
            let (h, p, t, w) = meshfmt::file::decode_case(&bytes).unwrap();
            assert_eq!(p, c.positions, "{}", c.name);
            assert_eq!(t, c.triangles, "{}", c.name);
            assert_eq!(w, c.wedges, "{}", c.name);
            assert_eq!(meshfmt::lib::config(&h), c.config, "{}", c.name);
        }
    }

    #[test]
    fn diff_names_the_first_differing_triangle() {
        let spec = &load_specs(&default_dir()).unwrap()[0];
        let case = Case::from_spec(spec).unwrap();
        let a = reference(&case).unwrap();
        let ga = Golden::from_outcome(&case, Backend::compiled(), &a).unwrap();
        let mut b = a.clone();
        b.header.ticks = 99; // measurement: ignored
        b.header.stack_high_water = 7;
        b.header.board = Board::Microbit;
        assert_eq!(
            judge(&case, Backend::compiled(), &ga, &b).unwrap(),
            Verdict::Identical
        );
        b.header.collapses += 1;
        b.triangles[3][1] += 1;
        match judge(&case, Backend::compiled(), &ga, &b).unwrap() {
            Verdict::Diff(d) => {
                assert!(d[0].starts_with("first differing triangle: #3:"), "{d:?}");
                assert!(d.iter().any(|l| l.contains("collapses")), "{d:?}");
            }
            v => panic!("{v:?}"),
        }
        b.header.status = Status::TooBig;
        assert!(matches!(
            judge(&case, Backend::compiled(), &ga, &b).unwrap(),
            Verdict::Skipped(_)
        ));
    }
}

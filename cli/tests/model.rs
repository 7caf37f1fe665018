//! The library's one call for a model (`Workspace::simplify_model`) gives what `host-sim
//! simplify` gives with its defaults: the same triangles, byte for byte, on seam-split and
//! multi-part meshes; and the plain `simplify` it replaces for such models cracks their seams.

use std::path::{Path, PathBuf};

use meshcheck::{check_with, MeshRef, Options};
use tinydecimate::{Config, ModelStorage, Storage};
use tinydecimate_cli::io::MeshData;

mod common;
use common::{run, text};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures")
        .join(name)
}

/// Storage sized to `m` (as a firmware caller sizes its `Workspace`).
struct Buffers {
    links: Vec<u32>,
    corners: Vec<[u32; 3]>,
    keys: Vec<f32>,
    flags: Vec<u8>,
}

impl Buffers {
    fn for_mesh(m: &MeshData) -> Self {
        let (nv, nt) = (m.positions.len(), m.triangles.len());
        Buffers {
            links: vec![0; 3 * nv],
            corners: vec![[0; 3]; nt],
            keys: vec![0.0; nv],
            flags: vec![0; nv],
        }
    }

    fn storage(&mut self) -> Storage<'_, u32> {
        Storage::new(
            &mut self.links,
            &mut self.corners,
            &mut self.keys,
            &mut self.flags,
        )
        .unwrap()
    }
}

/// The README's configuration for a model: the ratio and the CLI's default error limit.
fn model_config(m: &MeshData, ratio: f32) -> Config {
    Config::new()
        .with_ratio(ratio)
        .with_relative_error_limit(Config::MODEL_ERROR_LIMIT, &m.positions)
}

/// `simplify_model` with part pruning: the output triangles, in the caller's numbering.
fn library_model(m: &MeshData, ratio: f32) -> Vec<[u32; 3]> {
    let mut b = Buffers::for_mesh(m);
    let mut tris = m.triangles.clone();
    let mut wedges = vec![[0u32; 3]; tris.len()];
    let mut parts = vec![[0u32; 2]; m.positions.len()];
    let mut model = ModelStorage::new(&mut wedges).with_parts(&mut parts);
    let r = b
        .storage()
        .simplify_model(&m.positions, &mut tris, &mut model, &model_config(m, ratio))
        .unwrap();
    tris.truncate(r.triangles_out);
    tris
}

/// The plain one-liner with the same configuration.
fn library_plain(m: &MeshData, ratio: f32) -> Vec<[u32; 3]> {
    let mut b = Buffers::for_mesh(m);
    let mut tris = m.triangles.clone();
    let r = b
        .storage()
        .simplify(&m.positions, &mut tris, &model_config(m, ratio))
        .unwrap();
    tris.truncate(r.triangles_out);
    tris
}

/// `tinydecimate simplify` with its defaults, the input's numbering kept: the output triangles.
fn cli(name: &str, ratio: f32, dir: &Path) -> Vec<[u32; 3]> {
    let out = dir.join(format!("{name}-{ratio}.obj"));
    let o = run(&[
        "simplify",
        fixture(name).to_str().unwrap(),
        out.to_str().unwrap(),
        "--ratio",
        &ratio.to_string(),
        "--keep-numbering",
        "--force",
        "--engine",
        "exact",
    ]);
    assert!(o.status.success(), "{name}: {}", text(&o.stderr));
    tinydecimate_cli::io::load(&out).unwrap().triangles
}

/// The verdict of `out` against `m` with both welded by position, parts allowed to vanish.
fn welded_verdict(m: &MeshData, out: &[[u32; 3]]) -> meshcheck::Verdict {
    check_with(
        MeshRef {
            positions: &m.positions,
            triangles: &m.triangles,
        },
        MeshRef {
            positions: &m.positions,
            triangles: out,
        },
        &Options {
            welded: true,
            parts: true,
            ..Default::default()
        },
    )
}

#[test]
fn one_call_gives_the_clis_bytes() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "suzanne_seams.obj",
        "pins.obj",
        "wuson.obj",
        "pr2_sensor_mount.obj",
        "cow.obj",
    ] {
        let m = tinydecimate_cli::io::load(fixture(name)).unwrap();
        for ratio in [0.25, 0.1] {
            let lib = library_model(&m, ratio);
            assert_eq!(lib, cli(name, ratio, dir.path()), "{name} at {ratio}");
            let v = welded_verdict(&m, &lib);
            assert!(v.is_valid(), "{name} at {ratio}: {v}");
        }
    }
}

#[test]
fn the_plain_call_cracks_a_seam_split_model_and_the_model_call_does_not() {
    let m = tinydecimate_cli::io::load(fixture("suzanne_seams.obj")).unwrap();
    let plain = library_plain(&m, 0.1);
    let v = welded_verdict(&m, &plain);
    assert!(!v.is_valid(), "the plain call kept every seam closed: {v}");
    let model = library_model(&m, 0.1);
    assert!(
        model.len() < plain.len(),
        "{} vs {}",
        model.len(),
        plain.len()
    );
    let v = welded_verdict(&m, &model);
    assert!(v.is_valid(), "{v}");
}

#[test]
fn an_error_leaves_the_triangles_as_given() {
    let m = tinydecimate_cli::io::load(fixture("suzanne_seams.obj")).unwrap();
    let mut b = Buffers::for_mesh(&m);
    let mut tris = m.triangles.clone();
    let mut wedges = vec![[0u32; 3]; tris.len()];
    // Too few part links: refused after the weld renumbered the triangles.
    let mut parts = vec![[0u32; 2]; m.positions.len() - 1];
    let mut model = ModelStorage::new(&mut wedges).with_parts(&mut parts);
    let e = b
        .storage()
        .simplify_model(&m.positions, &mut tris, &mut model, &model_config(&m, 0.1))
        .unwrap_err();
    assert!(matches!(e, tinydecimate::Error::Capacity { .. }), "{e:?}");
    assert_eq!(tris, m.triangles);
    // A NaN position is refused by the build, also after the weld.
    let mut p = m.positions.clone();
    p[0][1] = f32::NAN;
    let mut wedges = vec![[0u32; 3]; tris.len()];
    let mut model = ModelStorage::<u32, u32>::new(&mut wedges);
    let e = b
        .storage()
        .simplify_model(&p, &mut tris, &mut model, &Config::new().with_ratio(0.1))
        .unwrap_err();
    assert!(
        matches!(e, tinydecimate::Error::NonFinitePosition { .. }),
        "{e:?}"
    );
    assert_eq!(tris, m.triangles);
}

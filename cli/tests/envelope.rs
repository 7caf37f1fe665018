//! The envelope bound (`tinydecimate::bound::Envelope`, simplification envelopes of Cohen et
//! al., survey seed 002) on every bench mesh: with `ε` at 0.5 % and 1 % of the bounding-box
//! diagonal, the symmetric Hausdorff distance Metro measures between the input and the result
//! (both directions) is at most `ε`, the result passes the shared validity check, and the run
//! removed triangles (so the distance test is not met by doing nothing). Built with
//! `TINYDECIMATE_RULE_OFF=bound` (the envelope's veto off) every test here fails on distance.

use std::path::{Path, PathBuf};

use tinydecimate::Config;
use tinydecimate_cli::io::MeshData;
use tinydecimate_cli::metro::{metro, MetroOptions};
use tinydecimate_cli::simplify::{simplify_with, OperatorArg, Run};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every bench mesh: the fixtures (OBJ and glTF) and the bench's own.
fn bench_meshes() -> Vec<PathBuf> {
    let mut v = Vec::new();
    for dir in ["tests/fixtures", "bench/meshes"] {
        for e in std::fs::read_dir(root().join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "obj" || x == "glb") {
                v.push(p);
            }
        }
    }
    v.sort();
    assert!(v.len() >= 15, "{v:?}");
    v
}

/// One bounded run: its output, the bound in input units and the symmetric Hausdorff distance.
fn bounded(mesh: &MeshData, fraction: f32, operator: OperatorArg) -> (MeshData, f64, f64) {
    let config = Config::new()
        .with_ratio(0.0)
        .with_error_limit(f32::INFINITY)
        .with_relative_max_error(fraction, &mesh.positions);
    // Seams welded by position, as the command line does by default: a seam-split asset
    // would otherwise be all borders, which the envelope keeps.
    let run = Run {
        operator,
        bounded: true,
        envelope: true,
        weld: true,
        ..Default::default()
    };
    let (out, _, _) = simplify_with(mesh, &config, &run).unwrap();
    // Samples scaled to the mesh, so that the largest mesh costs no more than a few seconds.
    let opts = MetroOptions {
        samples_per_triangle: (400_000.0 / mesh.triangles.len() as f64).clamp(2.0, 20.0),
        ..Default::default()
    };
    let m = metro(mesh, &out, &opts);
    let h = m.a_to_b.max.max(m.b_to_a.max);
    (out, f64::from(config.max_error()), h)
}

fn check(
    name: &str,
    mesh: &MeshData,
    out: &MeshData,
    bound: f64,
    h: f64,
    failed: &mut Vec<String>,
) {
    // Both welded by position, as the run welded them (a removal's output keeps the welded
    // numbering, a collapse's the input's).
    let v = meshcheck::check(
        &mesh.positions,
        &meshcheck::weld(&mesh.positions, &mesh.triangles),
        &meshcheck::weld(&out.positions, &out.triangles),
    );
    if !v.is_valid() {
        failed.push(format!("{name}: invalid output {v:?}"));
    }
    if h.is_nan() || h > bound {
        failed.push(format!("{name}: Hausdorff {h:e} above the bound {bound:e}"));
    }
    // The run did remove: every bench mesh loses at least a tenth (the self-touching CAD
    // assemblies least: their envelopes pinch where parts meet; docs/envelope.md).
    if out.triangles.len() * 10 > mesh.triangles.len() * 9 {
        failed.push(format!(
            "{name}: {} of {} triangles left",
            out.triangles.len(),
            mesh.triangles.len()
        ));
    }
}

/// Runs `operator` on each mesh at `ε` = 0.5 % and 1 % of the diagonal and checks each output.
fn assert_within_bound(paths: &[PathBuf], operator: OperatorArg) {
    let mut failed = Vec::new();
    for path in paths {
        let mesh = tinydecimate_cli::io::load(path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        for fraction in [0.005, 0.01] {
            let (out, bound, h) = bounded(&mesh, fraction, operator);
            let what = format!("{name} {fraction}");
            check(&what, &mesh, &out, bound, h, &mut failed);
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// Every bench mesh, edge collapse.
#[test]
fn every_bench_mesh_is_within_the_bound_both_ways() {
    assert_within_bound(&bench_meshes(), OperatorArg::Edge);
}

/// Vertex decimation's fill under the envelope: the same guarantee on the smaller meshes.
#[test]
fn vertex_decimation_fills_stay_within_the_bound() {
    let names = [
        "cow.obj",
        "fandisk.obj",
        "plate_holes.obj",
        "pins.obj",
        "suzanne_seams.obj",
    ];
    let paths: Vec<PathBuf> = names
        .iter()
        .map(|n| root().join("tests/fixtures").join(n))
        .collect();
    assert_within_bound(&paths, OperatorArg::VertexDecimation);
}

/// A mesh too small for a fine grid (`fuzz/regressions/envelope-cube-coarse-grid`: a cube of
/// side 10⁻²⁰): the grid is coarse but exact, so a cube within 0.5 % keeps its twelve faces.
/// Before, no grid fitted its index and every collapse went through, down to a tetrahedron.
#[test]
fn a_cube_keeps_its_faces_whatever_its_scale() {
    for scale in [1.0f32, 1e-20] {
        let corners = [
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let mesh = MeshData {
            positions: corners
                .iter()
                .map(|p: &[f32; 3]| p.map(|x| x * scale))
                .collect(),
            triangles: vec![
                [0, 1, 3],
                [1, 2, 3],
                [4, 5, 7],
                [5, 6, 7],
                [0, 3, 4],
                [3, 5, 4],
                [1, 7, 2],
                [7, 6, 2],
                [0, 4, 1],
                [4, 7, 1],
                [3, 2, 5],
                [2, 6, 5],
            ],
        };
        for operator in [OperatorArg::Edge, OperatorArg::VertexDecimation] {
            let (out, bound, h) = bounded(&mesh, 0.005, operator);
            assert_eq!(out.triangles.len(), 12, "{scale} {operator:?}");
            assert!(h <= bound, "{scale} {operator:?}");
        }
    }
}

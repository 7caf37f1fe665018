//! Progressive meshes: a simplification's collapse log turned into vertex splits must give back
//! exactly the input at full resolution and exactly the simplifier's mesh at every level.

mod common;
use common::*;
use tinydecimate::progressive::{ProgressiveError, Split, Storage};
use tinydecimate::EdgeCollapse;
use tinydecimate::{Config, Progressive, Stop, Target};

/// Triangles in input numbering, each rotated to start at its smallest index (winding kept),
/// sorted: the mesh as a set.
fn canonical(tris: &[Tri], order: Option<&[u32]>) -> Vec<Tri> {
    let mut v: Vec<Tri> = tris
        .iter()
        .map(|t| {
            let t = order.map_or(*t, |o| t.map(|i| o[i as usize]));
            let k = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect();
    v.sort_unstable();
    v
}

/// Compares two triangle sets, reporting only the size and the first differences.
fn same(a: Vec<Tri>, b: Vec<Tri>, what: &str) {
    if a != b {
        let only_a: Vec<_> = a.iter().filter(|t| !b.contains(t)).take(5).collect();
        let only_b: Vec<_> = b.iter().filter(|t| !a.contains(t)).take(5).collect();
        panic!(
            "{what}: {} vs {} triangles; only left {only_a:?}; only right {only_b:?}",
            a.len(),
            b.len()
        );
    }
}

struct Owned {
    tris: Vec<Tri>,
    links: Vec<Tri>,
    heads: Vec<u32>,
    splits: Vec<Split<u32>>,
    order: Vec<u32>,
    scratch: Vec<u32>,
}

impl Owned {
    fn new(m: &MeshData, log: usize) -> Self {
        let (v, t) = (m.positions.len(), m.triangles.len());
        Owned {
            tris: vec![[0; 3]; t],
            links: vec![[0; 3]; t],
            heads: vec![0; v],
            splits: vec![Split::EMPTY; log],
            order: vec![0; v],
            scratch: vec![0; t],
        }
    }

    fn build<'a>(
        &'a mut self,
        m: &MeshData,
        log: &[[u32; 2]],
    ) -> Result<Progressive<'a, u32>, ProgressiveError> {
        Progressive::from_log(
            &m.triangles,
            m.positions.len(),
            log,
            Storage {
                triangles: &mut self.tris,
                links: &mut self.links,
                heads: &mut self.heads,
                splits: &mut self.splits,
            },
            &mut self.order,
            &mut self.scratch,
        )
    }
}

fn levels_match(name: &str, m: &MeshData, config: Config) {
    let (log, base, _) = simplify_logged(m, &config);
    let mut o = Owned::new(m, log.len());
    let order = {
        let pm = o.build(m, &log).unwrap();
        // Full resolution: the input's triangles, each with its winding.
        let valid = simplify(m, &Config::new().with_ratio(1.0)).0.triangles;
        assert_eq!(pm.levels(), log.len(), "{name}");
        let full: Vec<Tri> = pm.triangles().to_vec();
        (full, valid)
    };
    let (full, valid) = order;
    let order = o.order.clone();
    same(
        canonical(&full, Some(&order)),
        canonical(&valid, None),
        &format!("{name}: full resolution"),
    );
    let mut pm = o.build(m, &log).unwrap();
    // The base: exactly the simplifier's output.
    pm.set_level(0);
    assert_eq!(pm.level(), 0);
    same(
        canonical(pm.triangles(), Some(&order)),
        canonical(&base, None),
        &format!("{name}: base"),
    );
    let base_bytes = pm.triangles().to_vec();
    // Intermediate levels: the simplifier's own output at that target count.
    let t = valid.len();
    for frac in [0.8, 0.5, 0.3] {
        let n = (t as f64 * frac) as usize;
        if n < base.len() {
            continue;
        }
        pm.set_level(n);
        let (out, r) = simplify(m, &config.with_target(Target::Triangles(n)));
        assert_eq!(r.triangles_out, pm.triangles().len(), "{name} at {n}");
        same(
            canonical(pm.triangles(), Some(&order)),
            canonical(&out.triangles, None),
            &format!("{name}: level at {n} triangles"),
        );
        // Every level is a valid mesh over the renumbered positions.
        let positions: Vec<[f32; 3]> = order.iter().map(|&i| m.positions[i as usize]).collect();
        let level = MeshData {
            positions: positions.clone(),
            triangles: pm.triangles().to_vec(),
        };
        let input = MeshData {
            positions,
            triangles: full.clone(),
        };
        verdict(&input, &level).assert_valid(name);
    }
    // Round trips in place are exact, bytes and all.
    pm.set_level(usize::MAX);
    assert_eq!(pm.triangles(), &full[..], "{name}: back to full");
    assert_eq!(pm.coarsen(usize::MAX), log.len());
    assert_eq!(pm.triangles(), &base_bytes[..], "{name}: back to base");
    assert_eq!(pm.refine(7), 7.min(log.len()));
    assert_eq!(pm.coarsen(3), 3.min(log.len()));
    pm.refine(usize::MAX);
    assert_eq!(pm.triangles(), &full[..], "{name}: full again");
}

#[test]
fn levels_are_the_simplifiers_meshes() {
    levels_match("grid", &grid(4, 3, 0.3), Config::new().with_ratio(0.0));
    levels_match(
        "cow greedy",
        &load_obj("cow.obj"),
        Config::new().with_ratio(0.1),
    );
    levels_match(
        "cow passes",
        &load_obj("cow.obj"),
        Config::paper().with_ratio(0.1),
    );
    levels_match(
        "plate_holes",
        &load_obj("plate_holes.obj"),
        Config::new().with_ratio(0.05),
    );
    levels_match("grid", &grid(20, 15, 0.3), Config::new().with_ratio(0.0));
    levels_match(
        "fin and pinch",
        &fin_and_pinch(12),
        Config::new().with_ratio(0.2),
    );
}

#[test]
fn a_full_log_stops_the_run_with_a_valid_mesh() {
    let m = load_obj("cow.obj");
    let mut tris = m.triangles.clone();
    let mut log = vec![[0u32; 2]; 100];
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let mut s = ws
        .start(
            tinydecimate::Positions::Read(&m.positions),
            &mut tris,
            &Config::new().with_ratio(0.1),
            tinydecimate::Builtin::new(),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .unwrap()
        .record_into(&mut log);
    while !s.step(u32::MAX) {}
    let r = s.finish();
    assert_eq!((r.stop, r.collapses), (Stop::LogFull, 100));
    drop(ws);
    let out = MeshData {
        positions: m.positions.clone(),
        triangles: tris[..r.triangles_out].to_vec(),
    };
    assert_valid("cow log full", &m, &out, &r);
}

#[test]
fn bad_logs_and_small_storage_are_typed_errors() {
    let m = load_obj("cow.obj");
    let (log, _, _) = simplify_logged(&m, &Config::new().with_ratio(0.5));
    let mut o = Owned::new(&m, log.len());
    // Not an edge.
    let mut bad = log.clone();
    bad[3] = [bad[3][0], bad[3][0] ^ 1];
    let far = (0..m.positions.len() as u32)
        .find(|&v| {
            m.triangles
                .iter()
                .all(|t| !(t.contains(&v) && t.contains(&bad[3][0])))
                && v != bad[3][0]
        })
        .unwrap();
    bad[3][1] = far;
    assert_eq!(
        o.build(&m, &bad).err(),
        Some(ProgressiveError::BadLog { entry: 3 })
    );
    // A vertex removed twice.
    let mut twice = log.clone();
    twice[5] = twice[2];
    assert_eq!(
        o.build(&m, &twice).err(),
        Some(ProgressiveError::BadLog { entry: 5 })
    );
    // Out of range.
    let mut oor = log.clone();
    oor[0][1] = m.positions.len() as u32;
    assert_eq!(
        o.build(&m, &oor).err(),
        Some(ProgressiveError::BadLog { entry: 0 })
    );
    // Too little storage.
    let mut small = Owned::new(&m, log.len() - 1);
    assert!(matches!(
        small.build(&m, &log).err(),
        Some(ProgressiveError::Capacity { what: "splits", .. })
    ));
    // The good log still builds with the same storage.
    assert!(o.build(&m, &log).is_ok());
}

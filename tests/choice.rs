//! `choice`: policies chosen at run time give, through `Storage::run_chosen`, the bytes the same
//! policies give as types through `Storage::start`, and its progress counts the removed
//! triangles.

mod common;

use common::{load_obj, MeshData, BIG};
use tinydecimate::bound::{self, Controls, NoBound};
use tinydecimate::choice::{Chosen, ChosenBound, ChosenCost, ChosenOperator};
use tinydecimate::cost::{Builtin, Energy, Placement, Samples, StoredQuadric, VertexQuadric};
use tinydecimate::{
    Config, EdgeCollapse, Error, Positions, Report, TriangleCollapse, VertexDecimation,
};

/// One run through `run_chosen`, with storage for every policy.
fn chosen(
    m: &MeshData,
    config: &Config,
    cost: u8,
    bounded: bool,
    operator: u8,
) -> Result<(Vec<[u32; 3]>, Report, usize), Error> {
    let mut tris = m.triangles.clone();
    let mut quadrics: Vec<VertexQuadric> = vec![[0.0; 10]; m.positions.len()];
    let mut samples: Vec<Samples> = vec![[0.0; 10]; m.positions.len()];
    let mut links = vec![0u32; bound::control_len(tris.len(), m.positions.len())];
    let cost = match cost {
        0 => ChosenCost::<0>::Builtin(Builtin::new()),
        1 => ChosenCost::Stored(StoredQuadric::new(&mut quadrics, Placement::Subset)),
        _ => ChosenCost::Energy(Energy::new(&mut samples)),
    };
    let bound = if bounded {
        ChosenBound::Controls(Controls::new(&m.triangles, &mut links))
    } else {
        ChosenBound::None
    };
    let operator = match operator {
        0 => ChosenOperator::Edge,
        1 => ChosenOperator::Triangle,
        _ => ChosenOperator::VertexDecimation(VertexDecimation::new()),
    };
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let mut last = 0;
    let report = ws.as_storage().run_chosen(
        Positions::Read(&m.positions),
        &mut tris,
        config,
        Chosen::new(cost, bound, operator).with_budget(64),
        |removed| {
            assert!(removed >= last, "progress went back");
            last = removed;
        },
    )?;
    tris.truncate(report.triangles_out);
    Ok((tris, report, last))
}

/// The same run through `start`, the policies as types.
fn typed(
    m: &MeshData,
    config: &Config,
    cost: u8,
    bounded: bool,
    operator: u8,
) -> Result<(Vec<[u32; 3]>, Report), Error> {
    let mut tris = m.triangles.clone();
    let mut quadrics: Vec<VertexQuadric> = vec![[0.0; 10]; m.positions.len()];
    let mut samples: Vec<Samples> = vec![[0.0; 10]; m.positions.len()];
    let mut links = vec![0u32; bound::control_len(tris.len(), m.positions.len())];
    let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
    let p = Positions::Read(&m.positions);
    macro_rules! go {
        ($cost:expr, $bound:expr) => {
            match operator {
                0 => ws
                    .start(p, &mut tris, config, $cost, $bound, EdgeCollapse)?
                    .run(),
                1 => ws
                    .start(p, &mut tris, config, $cost, $bound, TriangleCollapse)?
                    .run(),
                _ => ws
                    .start(p, &mut tris, config, $cost, $bound, VertexDecimation::new())?
                    .run(),
            }
        };
    }
    let report = match (cost, bounded) {
        (0, false) => go!(Builtin::new(), NoBound),
        (0, true) => go!(Builtin::new(), Controls::new(&m.triangles, &mut links)),
        (1, false) => go!(
            StoredQuadric::new(&mut quadrics, Placement::Subset),
            NoBound
        ),
        (1, true) => go!(
            StoredQuadric::new(&mut quadrics, Placement::Subset),
            Controls::new(&m.triangles, &mut links)
        ),
        (_, false) => go!(Energy::new(&mut samples), NoBound),
        (_, true) => go!(
            Energy::new(&mut samples),
            Controls::new(&m.triangles, &mut links)
        ),
    };
    tris.truncate(report.triangles_out);
    Ok((tris, report))
}

#[test]
fn a_chosen_run_gives_the_typed_runs_bytes() {
    let m = load_obj("cow.obj");
    let (mut runs, mut refused) = (0, 0);
    for cost in 0..3u8 {
        for bounded in [false, true] {
            for operator in 0..3u8 {
                // Only the edge collapse takes every cost; the others take the built-in one.
                if operator != 0 && cost != 0 {
                    continue;
                }
                let config = match (cost, bounded) {
                    (1, false) => Config::stored().with_ratio(0.25),
                    (1, true) => Config::stored()
                        .with_ratio(0.25)
                        .with_relative_max_error(0.01, &m.positions),
                    (_, false) => Config::new().with_ratio(0.25),
                    (_, true) => Config::new()
                        .with_ratio(0.25)
                        .with_relative_max_error(0.01, &m.positions),
                };
                let what = format!("cost {cost}, bounded {bounded}, operator {operator}");
                let (a, ra, removed) = match chosen(&m, &config, cost, bounded, operator) {
                    Ok(run) => run,
                    Err(e) => {
                        // Refused as `start` refuses it.
                        let typed = typed(&m, &config, cost, bounded, operator).map(|_| ());
                        assert_eq!(typed, Err(e), "{what}");
                        refused += 1;
                        continue;
                    }
                };
                let (b, rb) = typed(&m, &config, cost, bounded, operator).expect(&what);
                assert_eq!(ra, rb, "{what}");
                assert_eq!(a, b, "{what}");
                assert!(a.len() < m.triangles.len(), "{what}: nothing removed");
                assert_eq!(removed, m.triangles.len() - a.len(), "{what}: progress");
                runs += 1;
            }
        }
    }
    assert!(
        runs >= 7 && runs + refused == 10,
        "{runs} runs, {refused} refused"
    );
}

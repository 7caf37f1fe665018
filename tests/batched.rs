//! `Schedule::Batched`: meshoptimizer's pass structure over the greedy schedule's cost and
//! rules. What it promises, through the shared checker:
//!
//! * `the_cow_reaches_its_target`: valid, at the target, in more than one pass.
//! * `steps_give_the_one_shot_bytes`: budgets of 1 and 7 operations give the bytes and the
//!   report of a one-shot run (with and without an error limit).
//! * `the_error_limit_holds`: a spike the limit forbids cutting stops the run with
//!   `Stop::ErrorLimit`, every collapse made under the limit.
//! * `shared_meshes_stay_valid`: every shared mesh at 50 % and 10 %, the error limit of
//!   `tinydecimate simplify` on, valid and at the target or stopped for a reason.
//! * `stored_quadrics_and_twins`: stored quadrics (both placements) and a double-sided
//!   surface run under the batched schedule too.
//! * `the_papers_feature_rule` and `passes_are_capped`.
//! * `parts_vanish_whole` (with the `parts` feature): pruning under the batched schedule.

mod common;

/// Without the crate feature the schedule is refused before anything is touched.
#[cfg(not(feature = "batched"))]
#[test]
fn refused_without_the_feature() {
    use tinydecimate::{Config, ConfigField, Error, Schedule};
    let m = common::grid(4, 4, 0.1);
    let mut tris = m.triangles.clone();
    let mut ws = common::BIG.lock().unwrap_or_else(|e| e.into_inner());
    let r = ws.simplify(
        &m.positions,
        &mut tris,
        &Config::new().with_schedule(Schedule::Batched),
    );
    assert_eq!(
        r.map(|_| ()),
        Err(Error::InvalidConfig {
            field: ConfigField::Schedule
        })
    );
    assert_eq!(tris, m.triangles);
}

#[cfg(feature = "batched")]
mod on {
    use super::common::*;
    use tinydecimate::cost::VertexQuadric;
    use tinydecimate::{
        Builtin, Config, EdgeCollapse, NoBound, Placement, Positions, Report, Schedule, Stop,
        StoredQuadric, Target,
    };

    fn batched() -> Config {
        Config::new().with_schedule(Schedule::Batched)
    }

    /// Runs `config` on `m` in steps of `budget` operations (`u32::MAX`: one shot); the caller's
    /// whole buffer afterwards and the report.
    fn stepped(m: &MeshData, config: &Config, budget: u32) -> (Vec<[u32; 3]>, Report) {
        let mut tris = m.triangles.clone();
        let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
        let mut s = ws
            .start(
                Positions::Read(&m.positions),
                &mut tris,
                config,
                Builtin::new(),
                NoBound,
                EdgeCollapse,
            )
            .expect("start");
        while !s.step(budget) {}
        let r = s.finish();
        (tris, r)
    }

    #[test]
    fn the_cow_reaches_its_target() {
        let m = load_obj("cow.obj");
        let config = batched().with_ratio(0.1);
        let (out, r) = simplify(&m, &config);
        assert_eq!(r.stop, Stop::Target, "{r:?}");
        assert!(r.target_reached);
        assert_eq!(r.triangles_out, m.triangles.len() / 10);
        assert!(r.passes > 1, "{r:?}");
        // Each pass made a collapse: the logged counts fall.
        assert!(r.pass_triangles.windows(2).all(|w| w[1] < w[0]), "{r:?}");
        assert_valid("cow", &m, &out, &r);
        // Not the greedy order.
        let (greedy, _) = simplify(&m, &Config::new().with_ratio(0.1));
        assert_ne!(greedy.triangles, out.triangles);
    }

    #[test]
    fn steps_give_the_one_shot_bytes() {
        let cow = load_obj("cow.obj");
        let wave = grid(30, 20, 0.2);
        for (name, m, config) in [
            ("cow", &cow, batched().with_ratio(0.1)),
            (
                "cow, error limit",
                &cow,
                batched()
                    .with_ratio(0.02)
                    .with_relative_error_limit(0.01, &cow.positions),
            ),
            ("grid", &wave, batched().with_ratio(0.05)),
        ] {
            let (one, r1) = stepped(m, &config, u32::MAX);
            for budget in [1, 7] {
                let (b, rb) = stepped(m, &config, budget);
                assert_eq!(one, b, "{name}: budget {budget}");
                assert_eq!(r1, rb, "{name}: budget {budget}");
            }
            let (out, r) = output(&m.positions, one, r1);
            assert_valid(name, m, &out, &r);
        }
    }

    #[test]
    fn the_error_limit_holds() {
        // A flat grid with a tall spike in the middle: reaching 8 triangles would cut it.
        let mut m = grid(16, 16, 0.0);
        let apex = 8 * 17 + 8;
        m.positions[apex][2] = 0.3;
        let config = batched().with_target(Target::Triangles(8));
        let limit = 0.05;
        // A limit too high to refuse anything: the run cuts into the spike, with collapses over
        // the limit below (the last few triangles of the square may be refused by the shape rules).
        let (_, r) = simplify(&m, &config.with_error_limit(1e6));
        assert_ne!(r.stop, Stop::ErrorLimit, "{r:?}");
        assert!(r.triangles_out <= 16, "{r:?}");
        assert!(r.collapse_error > limit, "{}", r.collapse_error);
        let (out, r) = simplify(&m, &config.with_error_limit(limit));
        assert_eq!(r.stop, Stop::ErrorLimit, "{r:?}");
        assert!(!r.target_reached);
        assert!(r.over_limit > 0);
        assert!(r.collapse_error <= limit, "{}", r.collapse_error);
        assert!(out.triangles.iter().any(|t| t.contains(&(apex as u32))));
        assert!(out.triangles.len() * 4 < m.triangles.len(), "{r:?}");
        assert_valid("spike", &m, &out, &r);
        // On the cow: every collapse under the limit.
        let cow = load_obj("cow.obj");
        let limit = 0.01 * 12.711142;
        let (out, r) = simplify(&cow, &batched().with_ratio(0.01).with_error_limit(limit));
        assert_eq!(r.stop, Stop::ErrorLimit, "{r:?}");
        assert!(r.collapse_error <= limit, "{}", r.collapse_error);
        assert_valid("cow, limited", &cow, &out, &r);
    }

    #[test]
    fn shared_meshes_stay_valid() {
        let dir = shared_meshes();
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .expect("shared meshes")
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter(|n| n.ends_with(".obj"))
            .collect();
        names.sort();
        assert!(names.len() >= 10, "{names:?}");
        for name in &names {
            let m = load_obj(name);
            for ratio in [0.5, 0.1] {
                let config = batched()
                    .with_ratio(ratio)
                    .with_relative_error_limit(0.02, &m.positions);
                let (out, r) = simplify(&m, &config);
                assert!(
                    r.target_reached || matches!(r.stop, Stop::ErrorLimit | Stop::NoLegalCollapse),
                    "{name} at {ratio}: {r:?}"
                );
                assert_valid(&format!("{name} at {ratio}"), &m, &out, &r);
            }
        }
    }

    #[test]
    fn stored_quadrics_and_twins() {
        let m = load_obj("cow.obj");
        for placement in [Placement::Subset, Placement::Optimal] {
            let mut p = m.positions.clone();
            let mut tris = m.triangles.clone();
            let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; p.len()];
            let config = Config::stored()
                .with_schedule(Schedule::Batched)
                .with_ratio(0.1);
            let r = {
                let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
                ws.start(
                    Positions::Write(&mut p),
                    &mut tris,
                    &config,
                    StoredQuadric::new(&mut q, placement),
                    NoBound,
                    EdgeCollapse,
                )
                .expect("start")
                .run()
            };
            assert_eq!(r.stop, Stop::Target, "{placement:?}: {r:?}");
            let (out, r) = output(&p, tris, r);
            let moved = placement == Placement::Optimal;
            verdict_with(&m, &out, moved).assert_valid(&format!("stored {placement:?}"));
            assert_eq!(r.triangles_out, m.triangles.len() / 10);
        }
        // Both sides of a double-sided grid, the count asked for being the whole output's.
        let one = grid(20, 20, 0.1);
        let mut two = one.clone();
        two.triangles = one
            .triangles
            .iter()
            .flat_map(|&[a, b, c]| [[a, b, c], [a, c, b]])
            .collect();
        let (out, r) = simplify(&two, &batched().with_ratio(0.1));
        assert_eq!(r.twins, one.triangles.len());
        assert!(r.target_reached, "{r:?}");
        assert_valid("double-sided grid", &two, &out, &r);
    }

    #[test]
    fn the_papers_feature_rule() {
        // Feature vertices take no part in any collapse (`feature_targets` off).
        let m = load_obj("fandisk.obj");
        let config = batched().with_ratio(0.1).with_feature_targets(false);
        let (out, r) = simplify(&m, &config);
        assert!(r.feature_vertices > 0, "{r:?}");
        assert!(r.target_reached, "{r:?}");
        assert_valid("fandisk", &m, &out, &r);
    }

    #[test]
    fn passes_are_capped() {
        let m = load_obj("cow.obj");
        let (out, r) = simplify(&m, &batched().with_ratio(0.1).with_max_passes(2));
        assert_eq!(r.stop, Stop::MaxPasses, "{r:?}");
        assert_eq!(r.passes, 2);
        assert!(!r.target_reached);
        assert_valid("cow, two passes", &m, &out, &r);
    }

    /// A wavy sheet and ten small octahedra beside it: with `with_parts` the batched run
    /// reaches a target that needs parts to go, each part whole or gone, valid, and in steps
    /// of one operation gives the one-shot bytes.
    #[cfg(feature = "parts")]
    #[test]
    fn parts_vanish_whole() {
        let mut m = grid(24, 24, 0.15);
        for i in 0..10 {
            octahedron(&mut m, [0.1 * i as f32, 1.2, 0.05], 0.01 + 0.002 * i as f32);
        }
        let config = batched().with_ratio(0.05);
        let run = |budget: u32| {
            let mut tris = m.triangles.clone();
            let mut links = vec![[0u32; 2]; m.positions.len()];
            let mut ws = BIG.lock().unwrap_or_else(|e| e.into_inner());
            let mut s = ws
                .start(
                    Positions::Read(&m.positions),
                    &mut tris,
                    &config,
                    Builtin::new(),
                    NoBound,
                    EdgeCollapse,
                )
                .expect("start")
                .with_parts(&mut links)
                .expect("parts");
            while !s.step(budget) {}
            let r = s.finish();
            (tris, r)
        };
        let (one, r) = run(u32::MAX);
        let (stepped, rs) = run(1);
        assert_eq!(one, stepped);
        assert_eq!(r, rs);
        assert!(r.target_reached, "{r:?}");
        assert!(r.parts_removed > 0, "{r:?}");
        let (out, r) = output(&m.positions, one, r);
        for i in 0..10u32 {
            let part = 625 + 6 * i..625 + 6 * (i + 1);
            let inside = |t: &&[u32; 3]| t.iter().all(|v| part.contains(v));
            let kept = out.triangles.iter().filter(inside).count();
            assert!(kept == 0 || kept == 8, "part {i}: {kept} of 8");
        }
        let v = verdict_opts(
            &m,
            &out,
            &meshcheck::Options {
                parts: true,
                ..Default::default()
            },
        );
        v.assert_valid("sheet and bolts, batched");
        assert_eq!(v.parts_removed, r.parts_removed);
    }
}

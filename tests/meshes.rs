//! The real meshes of `tests/fixtures`: each simplifies to 25 % and 10 % with every
//! invariant holding, in both schedules.

mod common;
use common::*;
use tinydecimate::{Config, Schedule, Stop};

const MESHES: [&str; 8] = [
    "plate_holes.obj",
    "cow.obj",
    "spot.obj",
    "fandisk.obj",
    "rocker_arm.obj",
    "camelhead.obj",
    "stanford_bunny.obj",
    "armadillo.obj",
];

fn run(schedule: Schedule) {
    for name in MESHES {
        let input = load_obj(name);
        for ratio in [0.25f32, 0.1] {
            let config = Config::new().with_ratio(ratio).with_schedule(schedule);
            let t0 = std::time::Instant::now();
            let (output, report) = simplify(&input, &config);
            let dt = t0.elapsed();
            eprintln!(
                "{name} {schedule:?} {ratio}: {} -> {} (target {}, {:?}, passes {:?}) features {} in {dt:.2?} digest {:016x}",
                report.triangles_in,
                report.triangles_out,
                report.target_triangles,
                report.stop,
                report.pass_triangles,
                report.feature_vertices,
                digest(&output.triangles),
            );
            assert_valid(
                &format!("{name} {schedule:?} {ratio}"),
                &input,
                &output,
                &report,
            );
            assert!(
                report.triangles_out < report.triangles_in,
                "{name}: nothing removed"
            );
            if report.stop != Stop::Target {
                assert!(!report.target_reached);
            }
        }
    }
}

#[test]
fn greedy_keeps_every_invariant() {
    run(Schedule::Greedy);
}

#[test]
fn passes_keep_every_invariant() {
    run(Schedule::Passes);
}

//! The fast mode on the cow to 10 %, once, for instruction counts (crate feature `fast`):
//!
//! ```text
//! cargo build --release --features fast --example fast_cow
//! valgrind --tool=callgrind --toggle-collect='fast_cow::run' target/release/examples/fast_cow
//! ```
//!
//! `run` is the library call alone (`FastWorkspace::simplify`, or with `FAST_COW_LEAN=1` the
//! lean mode's `LeanWorkspace::simplify`; with `FAST_COW_INTEGER=1` either in integers, on the
//! positions put on the grid by `pipeline::quantise` before the call); reading the OBJ is
//! outside it. Optional arguments: an OBJ path (default `tests/fixtures/cow.obj`), a ratio (0.1) and
//! an output OBJ path.

use std::sync::Mutex;
use tinydecimate::pipeline::{FastWorkspace, Integer, LeanWorkspace};
use tinydecimate::{Config, Report};

/// u16 links (the cow's case), and u32 links for the larger meshes.
static SMALL: Mutex<FastWorkspace<u16, 65_535, 65_535>> = Mutex::new(FastWorkspace::new());
static LARGE: Mutex<FastWorkspace<u32, 65_536, 131_072>> = Mutex::new(FastWorkspace::new());
/// The lean mode's (`FAST_COW_LEAN=1`).
static LEAN_SMALL: Mutex<LeanWorkspace<u16, 65_535, 65_535>> = Mutex::new(LeanWorkspace::new());
static LEAN_LARGE: Mutex<LeanWorkspace<u32, 65_536, 131_072>> = Mutex::new(LeanWorkspace::new());

/// The integer workspaces (`FAST_COW_INTEGER=1`), u16 links.
static INT_FAST: Mutex<FastWorkspace<u16, 65_535, 65_535, Integer>> =
    Mutex::new(FastWorkspace::new());
static INT_LEAN: Mutex<LeanWorkspace<u16, 65_535, 65_535, Integer>> =
    Mutex::new(LeanWorkspace::new());

#[inline(never)]
fn run_integer(grid: &[[u16; 3]], tris: &mut [[u32; 3]], ratio: f32) -> Report {
    let config = Config::new().with_ratio(ratio);
    if std::env::var_os("FAST_COW_LEAN").is_some() {
        INT_LEAN.lock().unwrap().simplify(grid, tris, &config)
    } else {
        INT_FAST.lock().unwrap().simplify(grid, tris, &config)
    }
    .expect("simplify")
}

#[inline(never)]
fn run(positions: &[[f32; 3]], tris: &mut [[u32; 3]], ratio: f32) -> Report {
    let config = Config::new().with_ratio(ratio);
    let small = positions.len() < 65_535 && tris.len() < 65_535;
    if std::env::var_os("FAST_COW_LEAN").is_some() {
        return if small {
            LEAN_SMALL
                .lock()
                .unwrap()
                .simplify(positions, tris, &config)
        } else {
            LEAN_LARGE
                .lock()
                .unwrap()
                .simplify(positions, tris, &config)
        }
        .expect("simplify");
    }
    if positions.len() < 65_535 && tris.len() < 65_535 {
        SMALL.lock().unwrap().simplify(positions, tris, &config)
    } else {
        LARGE.lock().unwrap().simplify(positions, tris, &config)
    }
    .expect("simplify")
}

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/cow.obj").into());
    let ratio: f32 = args.next().map_or(0.1, |r| r.parse().expect("ratio"));
    let out = args.next();
    let text = std::fs::read_to_string(&path).expect("read OBJ");
    let (mut positions, mut tris) = (Vec::new(), Vec::new());
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let p: Vec<f32> = it.take(3).map(|x| x.parse().unwrap()).collect();
                positions.push([p[0], p[1], p[2]]);
            }
            Some("f") => {
                let f: Vec<u32> = it
                    .map(|x| x.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                    .collect();
                tris.push([f[0], f[1], f[2]]);
            }
            _ => {}
        }
    }
    let input = tris.clone();
    let integer = std::env::var_os("FAST_COW_INTEGER").is_some();
    let mut grid = vec![[0u16; 3]; positions.len()];
    if integer {
        tinydecimate::pipeline::quantise(&positions, &mut grid).expect("quantise");
    }
    let t0 = std::time::Instant::now();
    let r = if integer {
        run_integer(&grid, &mut tris, ratio)
    } else {
        run(&positions, &mut tris, ratio)
    };
    let dt = t0.elapsed();
    println!(
        "{path}: {} -> {} triangles, {} collapses, {} passes, {:?} in {dt:?}",
        r.triangles_in, r.triangles_out, r.collapses, r.passes, r.stop
    );
    if std::env::var("FAST_COW_DEBUG").is_ok() {
        println!(
            "passes {:?} rejected [{}] locked {} duplicates {}",
            r.pass_triangles, r.rejected, r.locked_vertices, r.duplicates_dropped
        );
    }
    // `FAST_COW_REPS=n`: the best of n more runs (host time).
    if let Some(n) = std::env::var("FAST_COW_REPS")
        .ok()
        .and_then(|n| n.parse::<u32>().ok())
    {
        let mut best = dt;
        for _ in 0..n {
            let mut t = input.clone();
            let t0 = std::time::Instant::now();
            run(&positions, &mut t, ratio);
            best = best.min(t0.elapsed());
        }
        println!("best of {n}: {best:?}");
    }
    if let Some(out) = out {
        let mut s = String::new();
        for p in &positions {
            s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        for t in &tris[..r.triangles_out] {
            s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        std::fs::write(out, s).expect("write OBJ");
    }
}

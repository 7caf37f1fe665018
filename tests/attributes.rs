//! Stored quadrics with vertex attributes (`AttributeQuadric`): on a flat grid, where every
//! geometric price is zero, a kink in the texture mapping (the UV gradient changes along one
//! column) is kept by the attribute term and lost without it; subset placement only (optimal is
//! refused), short storage is refused, and the geometric error limit is not fed the attribute
//! term.

use std::sync::Mutex;
use tinydecimate::cost::{AttributeQuadric, AttributeState, Placement, VertexQuadric};
use tinydecimate::{Capacity, Config, ConfigField, EdgeCollapse, Error, Positions, Workspace};

type Ws = Workspace<u32, 4_096, 8_192>;
static WS: Mutex<Ws> = Mutex::new(Workspace::new());

const N: usize = 24;
/// The column where the mapping kinks.
const KINK: usize = 9;

/// `u` of the mapping at `x`: slope 1 left of the kink, slope 4 right of it.
fn u_of(x: f32) -> f32 {
    let k = KINK as f32 / N as f32;
    if x <= k {
        x
    } else {
        k + 4.0 * (x - k)
    }
}

/// Positions, triangles and UVs.
type Grid = (Vec<[f32; 3]>, Vec<[u32; 3]>, Vec<[f32; 2]>);

/// A flat `N` x `N` grid on the unit square with UVs `(u_of(x), y)`.
fn kinked_grid() -> Grid {
    let w = N + 1;
    let mut p = Vec::new();
    let mut uv = Vec::new();
    for j in 0..w {
        for i in 0..w {
            let (x, y) = (i as f32 / N as f32, j as f32 / N as f32);
            p.push([x, y, 0.0]);
            uv.push([u_of(x), y]);
        }
    }
    let mut t = Vec::new();
    for j in 0..N {
        for i in 0..N {
            let a = (j * w + i) as u32;
            let (b, c, d) = (a + 1, a + w as u32, a + w as u32 + 1);
            // Alternate the diagonal so no direction is favoured.
            if (i + j) % 2 == 0 {
                t.push([a, b, d]);
                t.push([a, d, c]);
            } else {
                t.push([a, b, c]);
                t.push([b, d, c]);
            }
        }
    }
    (p, t, uv)
}

/// Runs the attribute cost with `weights` on the grid to `ratio`; the output triangles.
fn run(weights: [f32; 2], ratio: f32) -> Vec<[u32; 3]> {
    let (p, mut t, uv) = kinked_grid();
    let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; p.len()];
    let mut s = vec![AttributeState::<2>::ZERO; p.len()];
    let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
    let r = ws
        .start(
            Positions::Read(&p),
            &mut t,
            &Config::stored().with_ratio(ratio),
            AttributeQuadric::new(&mut q, &mut s, &uv, weights),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .expect("start")
        .run();
    assert!(r.target_reached, "{r:?}");
    t.truncate(r.triangles_out);
    t
}

/// The largest gap between the true `u` and the result's interpolated `u`, over a few points
/// of every output triangle (barycentric samples).
fn uv_gap(t: &[[u32; 3]]) -> f32 {
    let (p, _, uv) = kinked_grid();
    let mut worst = 0.0f32;
    for tri in t {
        let [a, b, c] = tri.map(|v| v as usize);
        for (wa, wb) in [(1.0 / 3.0, 1.0 / 3.0), (0.6, 0.2), (0.2, 0.6), (0.2, 0.2)] {
            let wc = 1.0 - wa - wb;
            let x = wa * p[a][0] + wb * p[b][0] + wc * p[c][0];
            let u = wa * uv[a][0] + wb * uv[b][0] + wc * uv[c][0];
            worst = worst.max((u - u_of(x)).abs());
        }
    }
    worst
}

/// The UV kink survives with the attribute term and is cut across without it (the test fails
/// if the term is switched off: the weight-zero run is the plain stored quadric).
#[test]
fn uv_kink_is_kept() {
    for ratio in [0.25, 0.1] {
        let plain = uv_gap(&run([0.0, 0.0], ratio));
        let with = uv_gap(&run([1.0, 1.0], ratio));
        assert!(with < 1e-4, "ratio {ratio}: gap with attributes {with}");
        assert!(
            plain > 0.01,
            "ratio {ratio}: gap without attributes {plain}"
        );
    }
}

/// Optimal placement is refused with a typed error, short storage with `Capacity`, a negative
/// weight with `InvalidConfig`.
#[test]
fn refusals() {
    let (p, mut t, uv) = kinked_grid();
    let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; p.len()];
    let mut s = vec![AttributeState::<2>::ZERO; p.len()];
    let e = AttributeQuadric::new(&mut q, &mut s, &uv, [1.0, 1.0])
        .with_placement(Placement::Optimal)
        .err();
    assert_eq!(
        e,
        Some(Error::InvalidConfig {
            field: ConfigField::Placement
        })
    );
    let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
    let short = &uv[..p.len() - 1];
    let before = t.clone();
    let e = ws
        .start(
            Positions::Read(&p),
            &mut t,
            &Config::stored().with_ratio(0.5),
            AttributeQuadric::new(&mut q, &mut s, short, [1.0, 1.0]),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .err();
    assert_eq!(
        e,
        Some(Error::Capacity {
            what: Capacity::Quadrics,
            needed: p.len(),
            available: p.len() - 1
        })
    );
    let mut s_short = vec![AttributeState::<2>::ZERO; 3];
    let e = ws
        .start(
            Positions::Read(&p),
            &mut t,
            &Config::stored().with_ratio(0.5),
            AttributeQuadric::new(&mut q, &mut s_short, &uv, [1.0, 1.0]),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .err();
    assert!(
        matches!(e, Some(Error::Capacity { available: 3, .. })),
        "{e:?}"
    );
    let e = ws
        .start(
            Positions::Read(&p),
            &mut t,
            &Config::stored().with_ratio(0.5),
            AttributeQuadric::new(&mut q, &mut s, &uv, [-1.0, 1.0]),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .err();
    assert_eq!(
        e,
        Some(Error::InvalidConfig {
            field: ConfigField::Cost
        })
    );
    assert_eq!(t, before);
}

/// The error limit is geometric: on the flat grid every collapse's geometric error is zero, so
/// a zero limit stops nothing the attribute term prices.
#[test]
fn error_limit_is_geometric() {
    let (p, mut t, uv) = kinked_grid();
    let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; p.len()];
    let mut s = vec![AttributeState::<2>::ZERO; p.len()];
    let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
    let r = ws
        .start(
            Positions::Read(&p),
            &mut t,
            &Config::stored().with_ratio(0.1).with_error_limit(1e-12),
            AttributeQuadric::new(&mut q, &mut s, &uv, [1.0, 1.0]),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .expect("start")
        .run();
    assert_eq!(r.over_limit, 0, "{r:?}");
}

/// The kinked grid with a UV seam at column `SEAM` (left of the kink): the right chart's
/// vertices on the seam are copies, and its `u` is shifted by 5. Returns the mesh, UVs and each
/// vertex's chart.
#[cfg(feature = "seams")]
fn kinked_grid_with_seam() -> (Grid, Vec<u8>) {
    const SEAM: usize = 4;
    let (mut p, mut t, mut uv) = kinked_grid();
    let w = N + 1;
    let mut chart: Vec<u8> = (0..p.len()).map(|v| u8::from(v % w > SEAM)).collect();
    let mut copy = vec![u32::MAX; p.len()];
    for j in 0..w {
        let v = j * w + SEAM;
        copy[v] = p.len() as u32;
        p.push(p[v]);
        uv.push([uv[v][0] + 5.0, uv[v][1]]);
        chart.push(1);
    }
    for tri in &mut t {
        // A triangle right of the seam column takes the copies.
        if tri.iter().any(|&v| v as usize % w > SEAM) {
            for v in tri.iter_mut() {
                if copy[*v as usize] != u32::MAX {
                    *v = copy[*v as usize];
                }
            }
        }
    }
    for (v, c) in uv.iter_mut().zip(&chart) {
        if *c == 1 && v[0] < 5.0 {
            v[0] += 5.0;
        }
    }
    ((p, t, uv), chart)
}

/// Welded seams: each triangle's gradient comes from its own wedges, so the seam's jump in `u`
/// is not read as a gradient; the kink is still kept, and lost without the attribute term.
#[cfg(feature = "seams")]
#[test]
fn uv_kink_is_kept_with_welded_seams() {
    let ((p, t0, uv), chart) = kinked_grid_with_seam();
    let run = |weights: [f32; 2]| {
        let mut t = t0.clone();
        let mut wedges = vec![[0u32; 3]; t.len()];
        let mut order = vec![0u32; p.len()];
        let moved = tinydecimate::seam::weld(&p, &mut t, &mut wedges, &mut order).expect("weld");
        assert!(moved > 0);
        let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; p.len()];
        let mut s = vec![AttributeState::<2>::ZERO; p.len()];
        let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
        let r = ws
            .start(
                Positions::Read(&p),
                &mut t,
                &Config::stored().with_ratio(0.2),
                AttributeQuadric::new(&mut q, &mut s, &uv, weights),
                tinydecimate::NoBound,
                EdgeCollapse,
            )
            .expect("start")
            .with_wedges(&mut wedges, tinydecimate::seam::SeamCorners::Move)
            .expect("wedges")
            .run();
        assert!(r.target_reached, "{r:?}");
        t.truncate(r.triangles_out);
        // The largest gap between the chart's true u and the interpolated one.
        let mut worst = 0.0f32;
        for tri in &t {
            let [a, b, c] = tri.map(|v| v as usize);
            assert!(
                chart[a] == chart[b] && chart[b] == chart[c],
                "a triangle across the seam"
            );
            let shift = 5.0 * f32::from(chart[a]);
            for (wa, wb) in [(1.0 / 3.0, 1.0 / 3.0), (0.6, 0.2), (0.2, 0.6), (0.2, 0.2)] {
                let wc = 1.0 - wa - wb;
                let x = wa * p[a][0] + wb * p[b][0] + wc * p[c][0];
                let u = wa * uv[a][0] + wb * uv[b][0] + wc * uv[c][0];
                worst = worst.max((u - shift - u_of(x)).abs());
            }
        }
        worst
    };
    let with = run([1.0, 1.0]);
    let plain = run([0.0, 0.0]);
    assert!(with < 1e-4, "gap with attributes {with}");
    assert!(plain > 0.01, "gap without attributes {plain}");
}

/// Welded seams: the states hold the charts' own gradients (`u` rises at most 4 per unit of
/// `x`, and the engine's normalisation does not scale this grid: 4 per normalised unit);
/// reading the seam's jump of 5 across one cell as a gradient (the representative's `u` for a
/// corner on the other chart) gives about 50.
#[cfg(feature = "seams")]
#[test]
fn welded_gradients_are_the_charts_own() {
    let ((p, mut t, uv), _) = kinked_grid_with_seam();
    let mut wedges = vec![[0u32; 3]; t.len()];
    let mut order = vec![0u32; p.len()];
    tinydecimate::seam::weld(&p, &mut t, &mut wedges, &mut order).expect("weld");
    let mut q: Vec<VertexQuadric> = vec![[0.0; 10]; p.len()];
    let mut s = vec![AttributeState::<2>::ZERO; p.len()];
    {
        let mut ws = WS.lock().unwrap_or_else(|e| e.into_inner());
        ws.start(
            Positions::Read(&p),
            &mut t,
            &Config::stored().with_ratio(0.9),
            AttributeQuadric::new(&mut q, &mut s, &uv, [1.0, 1.0]),
            tinydecimate::NoBound,
            EdgeCollapse,
        )
        .expect("start")
        .with_wedges(&mut wedges, tinydecimate::seam::SeamCorners::Move)
        .expect("wedges")
        .run();
    }
    let used = s.iter().filter(|s| s.w > 0.0).count();
    assert!(used > 100, "{used} states");
    for (v, s) in s.iter().enumerate().filter(|(_, s)| s.w > 0.0) {
        let g = s.g[0];
        let mean = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt() / s.w;
        assert!(mean <= 4.01, "vertex {v}: mean u gradient {mean}");
    }
}

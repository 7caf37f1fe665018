//! Link-time proof that tinydecimate cannot panic.
//!
//! The panic handler calls `rust_panic_reachable`, which is defined nowhere. After LTO every
//! call that can still reach a panic (bounds checks, `unwrap`, overflow checks, `unreachable!`,
//! slicing, division by zero, ...) refers to it, so the link fails iff a panic path survives
//! optimisation. Every public entry point is called, with inputs the optimiser cannot see
//! (`read_volatile`, `black_box`), for both index types and both link types (the pipeline's
//! in both arithmetics).
//!
//! Run `./check.sh` (from any directory).
#![no_std]
#![no_main]

use core::fmt::Write;
use core::hint::black_box;

use cortex_m_rt::entry;
use tinydecimate::bound::{control_len, Bound};
use tinydecimate::cluster::{
    cluster_then_collapse, ClusterConfig, ClusterError, Clusterer, Grid, GridChoice, PositionFn,
    Quadrics, Scratch, SliceSource, Source, ThenCollapseError, KEY_LANES,
};
use tinydecimate::cost::{
    error, AttributeQuadric, AttributeState, Builtin, Cost, Energy, Move, NormalVariation,
    Placement, Quadric, StoredQuadric, VertexQuadric,
};
use tinydecimate::operator::Operator;
use tinydecimate::pipeline::{quantise, Arithmetic, Float, Integer};
use tinydecimate::progressive::{Split, Storage};
use tinydecimate::seam::SeamCorners;
use tinydecimate::stream::{self, Decoder};
use tinydecimate::{
    Config, CostKind, EdgeCollapse, FeatureMode, Fill, Index, ModelStorage, NoBound, Positions,
    Progressive, Report, Schedule, Simplifier, Target, TriangleCollapse, VertexDecimation,
    Workspace,
};

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    extern "C" {
        /// Defined nowhere: linking fails if any panic is reachable.
        fn rust_panic_reachable() -> !;
    }
    // SAFETY: never linked; the whole point is that this call must be dead code.
    unsafe { rust_panic_reachable() }
}

/// Opaque inputs: whatever is in RAM at run time, as far as the optimiser knows.
static INPUT: [u32; 16] = [0; 16];

fn input(k: usize) -> u32 {
    // `k & 15` keeps the index provably in range (no bounds check of our own).
    // SAFETY: a valid, aligned reference to a static.
    unsafe { core::ptr::read_volatile(&INPUT[k & 15]) }
}

fn opaque_f32(k: usize) -> f32 {
    f32::from_bits(input(k))
}

fn opaque_config() -> Config {
    let c = Config::new()
        .with_schedule(if input(0) & 1 == 0 {
            Schedule::Greedy
        } else {
            Schedule::Passes
        })
        .with_cost(if input(0) & 2 == 0 {
            CostKind::Quadric
        } else {
            CostKind::NormalVariation
        })
        .with_target(if input(6) & 16 == 0 {
            Target::Ratio(opaque_f32(2))
        } else {
            Target::Triangles(input(1) as usize)
        })
        .with_max_cost(opaque_f32(3))
        .with_max_passes(input(4))
        .with_lambda(opaque_f32(5))
        .with_features(input(6) & 1 == 0)
        .with_feature_mode(if input(6) & 2 == 0 {
            FeatureMode::Paper
        } else {
            FeatureMode::ValenceNormalized
        })
        .with_feature_targets(input(6) & 4 == 0)
        .with_max_normal_turn(opaque_f32(7))
        .with_min_quality(opaque_f32(8))
        .with_boundary_weight(opaque_f32(9))
        .with_max_error(opaque_f32(19))
        .with_error_limit(opaque_f32(24))
        .with_control_angle(opaque_f32(20))
        .with_prune_parts(input(6) & 8 == 0);
    // The other constructors, and the builders again on them.
    let b = black_box(Config::paper())
        .with_schedule(c.schedule())
        .with_ratio(opaque_f32(10))
        .with_target(Target::Triangles(input(11) as usize))
        .with_lambda(opaque_f32(12))
        .with_feature_mode(c.feature_mode())
        .with_max_passes(input(13))
        .with_max_cost(opaque_f32(14))
        .with_max_error(opaque_f32(21))
        .with_error_limit(opaque_f32(25))
        .with_prune_parts(input(6) & 32 == 0)
        .with_cost(c.cost());
    black_box(Config::new().with_relative_max_error(opaque_f32(22), &[[opaque_f32(23); 3]; 4]));
    black_box(Config::default());
    black_box(Config::new());
    if input(15) & 1 == 0 {
        c
    } else {
        b
    }
}

/// A `core::fmt::Write` sink into a fixed buffer, itself panic-free.
struct Sink {
    buf: [u8; 160],
    len: usize,
}

impl Write for Sink {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        for &b in s.as_bytes() {
            match self.buf.get_mut(self.len) {
                Some(slot) => {
                    *slot = b;
                    self.len += 1;
                }
                None => return Err(core::fmt::Error),
            }
        }
        Ok(())
    }
}

fn display(e: &dyn core::fmt::Display) {
    let mut sink = Sink {
        buf: [0; 160],
        len: 0,
    };
    let _ = black_box(write!(sink, "{e}"));
    black_box(&sink.buf);
    black_box(sink.len);
}

fn use_report(r: &Report) {
    black_box(r.rejected.total());
    black_box(r.clone());
    black_box(r);
}

fn drive<'a, L: Index, I: Index, C: Cost, B: Bound<'a, I>, O: Operator>(
    mut s: Simplifier<'a, L, I, C, B, O>,
) {
    let budget = input(0);
    loop {
        let done = s.step(budget);
        black_box(s.live_triangles());
        use_report(&s.report());
        for t in s.triangles() {
            black_box(t);
        }
        black_box(s.buffer());
        let v = input(1) as usize;
        black_box(s.is_feature(v));
        black_box(s.is_used(v));
        if done || input(2) == 0 {
            break;
        }
    }
    use_report(&s.finish());
}

fn run<L: Index, I: Index, const V: usize, const T: usize>() {
    let mut ws = black_box(Workspace::<L, V, T>::new());
    let mut ws_default = black_box(Workspace::<L, V, T>::default());
    black_box(Workspace::<L, V, T>::BYTES);
    let positions: [[f32; 3]; V] = black_box([[0.0; 3]; V]);
    let mut tris: [[I; 3]; T] = black_box([[I::ZERO; 3]; T]);
    let (np, nt) = (input(3) as usize, input(4) as usize);
    let (Some(p), Some(t)) = (positions.get(..np), tris.get_mut(..nt)) else {
        return;
    };
    let config = opaque_config();
    if let Err(e) = config.validate() {
        display(&e);
    }

    match ws.simplify(p, t, &config) {
        Ok(r) => use_report(&r),
        Err(e) => display(&e),
    }
    // A model's one call: seams welded, parts pruned, either kind of seam corner.
    let mut wedges: [[I; 3]; T] = black_box([[I::ZERO; 3]; T]);
    let mut parts: [[L; 2]; V] = black_box([[L::ZERO; 2]; V]);
    let (nw, nl) = (input(9) as usize, input(10) as usize);
    if let (Some(w), Some(l)) = (wedges.get_mut(..nw), parts.get_mut(..nl)) {
        let corners = if input(11) & 1 == 0 {
            SeamCorners::Lock
        } else {
            SeamCorners::Move
        };
        let mut model = ModelStorage::new(w).with_corners(corners);
        if input(11) & 2 == 0 {
            model = model.with_parts(l);
        }
        match ws.simplify_model(p, t, &mut model, &config) {
            Ok(r) => use_report(&r),
            Err(e) => display(&e),
        }
    }
    match ws_default.start(
        Positions::Read(p),
        t,
        &config,
        Builtin::new(),
        NoBound,
        EdgeCollapse,
    ) {
        Ok(s) => drive(s),
        Err(e) => display(&e),
    }
    match ws.start(
        Positions::Read(p),
        t,
        &config,
        Builtin::new(),
        NoBound,
        TriangleCollapse,
    ) {
        Ok(s) => drive(s),
        Err(e) => display(&e),
    }
    let decimation = VertexDecimation::new()
        .with_feature_angle(opaque_f32(6))
        .with_feature_growth(opaque_f32(7), opaque_f32(8))
        .with_min_aspect(opaque_f32(9))
        .with_fill(if input(13) & 1 == 0 {
            Fill::Fit
        } else {
            Fill::Shape
        });
    match ws.start(
        Positions::Read(p),
        t,
        &config,
        Builtin::new(),
        NoBound,
        decimation,
    ) {
        Ok(s) => drive(s),
        Err(e) => display(&e),
    }
    let nv = NormalVariation::new();
    match ws.start(Positions::Read(p), t, &config, nv, NoBound, EdgeCollapse) {
        Ok(s) => drive(s),
        Err(e) => display(&e),
    }
    let pd = Quadric::new();
    match ws.start(Positions::Read(p), t, &config, pd, NoBound, EdgeCollapse) {
        Ok(s) => drive(s),
        Err(e) => display(&e),
    }
    // The batched schedule (crate feature `batched`).
    match ws.start(
        Positions::Read(p),
        t,
        &config.with_schedule(Schedule::Batched),
        Builtin::new(),
        NoBound,
        EdgeCollapse,
    ) {
        Ok(s) => drive(s),
        Err(e) => display(&e),
    }
    // Stored quadrics, both placements, one-shot and stepped.
    let mut quadrics: [VertexQuadric; V] = black_box([[0.0; 10]; V]);
    let mut moving: [[f32; 3]; V] = black_box([[0.0; 3]; V]);
    let nq = input(11) as usize;
    if let (Some(q), Some(mp)) = (quadrics.get_mut(..nq), moving.get_mut(..np)) {
        match ws
            .start(
                Positions::Read(p),
                t,
                &config,
                StoredQuadric::new(q, Placement::Subset),
                NoBound,
                EdgeCollapse,
            )
            .map(|s| s.run())
        {
            Ok(r) => use_report(&r),
            Err(e) => display(&e),
        }
        match ws
            .start(
                Positions::Write(mp),
                t,
                &config,
                StoredQuadric::new(q, Placement::Optimal),
                NoBound,
                EdgeCollapse,
            )
            .map(|s| s.run())
        {
            Ok(r) => use_report(&r),
            Err(e) => display(&e),
        }
        // Hoppe's energy: its samples in the quadrics' storage.
        match ws
            .start(
                Positions::Read(p),
                t,
                &config,
                Energy::new(q).with_weights(opaque_f32(14), opaque_f32(15)),
                NoBound,
                EdgeCollapse,
            )
            .map(|s| s.run())
        {
            Ok(r) => use_report(&r),
            Err(e) => display(&e),
        }
        let placement = if input(12) & 1 == 0 {
            Placement::Subset
        } else {
            Placement::Optimal
        };
        let sq = StoredQuadric::new(q, placement);
        black_box((
            sq.boundary_weight(),
            tinydecimate::cost::Cost::placement(&sq),
            sq.quadric(input(14) as usize),
        ));
        match ws.start(Positions::Write(mp), t, &config, sq, NoBound, EdgeCollapse) {
            Ok(s) => {
                black_box(s.position(input(15) as usize));
                drive(s)
            }
            Err(e) => display(&e),
        }
        black_box(&moving);
        // Stored quadrics with attributes (UV and normal), subset placement.
        let mut states: [AttributeState<5>; V] = black_box([AttributeState::ZERO; V]);
        let values: [[f32; 5]; V] = black_box([[0.0; 5]; V]);
        let (ns, na) = (input(13) as usize, input(14) as usize);
        if let (Some(st), Some(a)) = (states.get_mut(..ns), values.get(..na)) {
            let w = [
                opaque_f32(1),
                opaque_f32(1),
                opaque_f32(2),
                opaque_f32(2),
                opaque_f32(2),
            ];
            match AttributeQuadric::new(q, st, a, w).with_placement(placement_of(input(16))) {
                Ok(cost) => {
                    black_box((cost.state(input(15) as usize), cost.geometry().placement()));
                    match ws.start(Positions::Read(p), t, &config, cost, NoBound, EdgeCollapse) {
                        Ok(s) => drive(s),
                        Err(e) => display(&e),
                    }
                }
                Err(e) => display(&e),
            }
        }
    }
    // The error bound: control points over the original triangles, u16 and u32 links.
    let original: [[I; 3]; T] = black_box([[I::ZERO; 3]; T]);
    let mut links16: [u16; 1024] = black_box([0; 1024]);
    let mut links32: [u32; 1024] = black_box([0; 1024]);
    let nl = input(12) as usize;
    if let (Some(o), Some(l16), Some(l32)) = (
        original.get(..input(13) as usize),
        links16.get_mut(..nl),
        links32.get_mut(..nl),
    ) {
        black_box(control_len(input(14) as usize, input(15) as usize));
        let bound = tinydecimate::Controls::new(o, l16);
        match ws.start(
            Positions::Read(p),
            t,
            &config,
            Builtin::new(),
            bound,
            EdgeCollapse,
        ) {
            Ok(s) => use_report(&s.run()),
            Err(e) => display(&e),
        }
        let bound = tinydecimate::Controls::new(o, l32);
        match ws.start(
            Positions::Read(p),
            t,
            &config,
            Builtin::new(),
            bound,
            EdgeCollapse,
        ) {
            Ok(s) => drive(s),
            Err(e) => display(&e),
        }
        // The envelope bound, with the edge collapse and with vertex decimation.
        let mut shell: [[[f32; 3]; 2]; 256] = black_box([[[0.0; 3]; 2]; 256]);
        if let Some(sh) = shell.get_mut(..input(17) as usize) {
            let bound = tinydecimate::Envelope::new(o, sh, l16);
            match ws.start(Positions::Read(p), t, &config, Builtin::new(), bound, EdgeCollapse) {
                Ok(s) => drive(s),
                Err(e) => display(&e),
            }
        }
        if let Some(sh) = shell.get_mut(..input(18) as usize) {
            black_box(tinydecimate::bound::index_len(input(19) as usize));
            let bound = tinydecimate::Envelope::new(o, sh, l32);
            let op = VertexDecimation::new();
            match ws.start(Positions::Read(p), t, &config, Builtin::new(), bound, op) {
                Ok(s) => drive(s),
                Err(e) => display(&e),
            }
        }
        // Stored quadrics with a bound.
        if let Some(q) = quadrics.get_mut(..nq) {
            let bound = tinydecimate::Controls::new(o, l32);
            let cost = StoredQuadric::new(q, placement_of(input(16)));
            match ws.start(Positions::Read(p), t, &config, cost, bound, EdgeCollapse) {
                Ok(s) => drive(s),
                Err(e) => display(&e),
            }
        }
    }
    black_box(&tris);

    // The cost trait's methods by themselves.
    let m = Move {
        d: [opaque_f32(1), opaque_f32(2), opaque_f32(3)],
        retreat2: opaque_f32(4),
        turn: opaque_f32(5),
        from: input(16) as usize,
        to: input(17) as usize,
        p_from: [opaque_f32(1), opaque_f32(3), opaque_f32(5)],
        p_to: [opaque_f32(2), opaque_f32(4), opaque_f32(6)],
        keep: input(18) & 1 == 0,
    };
    black_box(error(&[opaque_f32(7); 10], m.p_to));
    let n = [opaque_f32(6), opaque_f32(7), opaque_f32(10)];
    let (mut pd, mut nv) = (pd, nv);
    let _ = pd.configure(&config, input(8) as usize);
    let _ = nv.configure(&config, input(9) as usize);
    pd.round(opaque_f32(11));
    let mut fan = pd.empty();
    pd.add(&mut fan, n, opaque_f32(12));
    black_box(pd.price(&fan, &m));
    let mut unit = nv.empty();
    nv.add(&mut unit, n, opaque_f32(12));
    black_box(nv.price(&unit, &m));
    let mut b = Builtin::new();
    let _ = b.configure(&config, input(10) as usize);
    b.round(opaque_f32(13));
    let mut bf = b.empty();
    b.add(&mut bf, n, opaque_f32(14));
    black_box((
        b.price(&bf, &m),
        b.needs_turn(),
        pd.needs_turn(),
        nv.needs_turn(),
    ));

    // Index.
    let i = I::from_usize(input(9) as usize);
    black_box(i.map(Index::to_usize));
    black_box(I::narrow(input(10) as usize).to_usize());
    black_box((I::NIL, I::COUNT, L::NIL, L::COUNT));
}

/// The progressive-mesh entry points: a logged simplification, the splits built from it,
/// the slider, the stream encoder and the incremental decoder on opaque bytes.
fn progressive<I: Index, const V: usize, const T: usize>() {
    let mut ws = black_box(Workspace::<I, V, T>::new());
    let positions: [[f32; 3]; V] = black_box([[0.0; 3]; V]);
    let input_tris: [[I; 3]; T] = black_box([[I::ZERO; 3]; T]);
    let mut tris = input_tris;
    let mut log: [[I; 2]; V] = black_box([[I::ZERO; 2]; V]);
    let (np, nt, nl) = (input(3) as usize, input(4) as usize, input(5) as usize);
    let (Some(p), Some(t), Some(l), Some(orig)) = (
        positions.get(..np),
        tris.get_mut(..nt),
        log.get_mut(..nl),
        input_tris.get(..nt),
    ) else {
        return;
    };
    let config = opaque_config();
    let logged = match ws.start(
        Positions::Read(p),
        t,
        &config,
        Builtin::new(),
        NoBound,
        EdgeCollapse,
    ) {
        Ok(s) => {
            let mut s = s.record_into(l);
            while !s.step(input(0)) {
                if input(1) == 0 {
                    break;
                }
            }
            let n = s.records().len();
            use_report(&s.finish());
            n
        }
        Err(e) => {
            display(&e);
            0
        }
    };
    let mut st_tris = [[I::ZERO; 3]; T];
    let mut links = [[I::ZERO; 3]; T];
    let mut heads = [I::ZERO; V];
    let mut splits = [Split::<I>::EMPTY; V];
    let mut order = [I::ZERO; V];
    let mut scratch = [I::ZERO; T];
    let storage = Storage {
        triangles: &mut st_tris,
        links: &mut links,
        heads: &mut heads,
        splits: &mut splits,
    };
    let used = log.get(..logged).unwrap_or(&[]);
    let mut out = [0u8; 512];
    match Progressive::from_log(orig, np, used, storage, &mut order, &mut scratch) {
        Ok(mut pm) => {
            black_box(pm.refine(input(6) as usize));
            black_box(pm.coarsen(input(7) as usize));
            pm.set_level(input(8) as usize);
            black_box((pm.triangles(), pm.vertices(), pm.level(), pm.levels()));
            black_box((pm.base_triangles(), pm.base_vertices(), pm.full_triangles()));
            black_box(pm.splits());
            let q = input(9) & 1 == 0;
            match stream::encode(&mut pm, p, &order, q, input(10) as u16, &mut out) {
                Ok(e) => {
                    black_box(e);
                }
                Err(e) => display(&e),
            }
        }
        Err(e) => display(&e),
    }
    // The decoder on opaque bytes, fed in opaque pieces.
    let mut d_tris = [[I::ZERO; 3]; T];
    let mut d_links = [[I::ZERO; 3]; T];
    let mut d_heads = [I::ZERO; V];
    let mut d_splits = [Split::<I>::EMPTY; V];
    let mut d_pos = [[0f32; 3]; V];
    let mut buf = [0u8; 300];
    let mut d = Decoder::new(
        Storage {
            triangles: &mut d_tris,
            links: &mut d_links,
            heads: &mut d_heads,
            splits: &mut d_splits,
        },
        &mut d_pos,
        &mut buf,
    );
    let bytes = black_box(out);
    let piece = input(11) as usize;
    let mut at = 0;
    while at < bytes.len() {
        let end = at.saturating_add(piece).clamp(at + 1, bytes.len());
        if let Err(e) = d.push(bytes.get(at..end).unwrap_or(&[])) {
            display(&e);
        }
        at = end;
    }
    if let Err(e) = d.finish() {
        display(&e);
    }
    black_box((d.header(), d.is_complete(), d.positions()));
    d.progressive().set_level(input(12) as usize);
    black_box(d.mesh().triangles());
    black_box(stream::crc32(&bytes));
}

/// A re-readable source whose triangles and positions are opaque, read in chunks of opaque
/// size (the clusterer's entry points on input the optimiser cannot see).
struct Opaque {
    at: u32,
}

impl Source for Opaque {
    fn rewind(&mut self) -> bool {
        self.at = 0;
        input(14) & 1 == 0
    }
    fn read(&mut self, buf: &mut [[u32; 3]]) -> usize {
        let n = (input(self.at as usize) as usize).min(buf.len());
        for (i, t) in buf.iter_mut().take(n).enumerate() {
            *t = [input(i), input(i + 1), input(i + 2)];
        }
        self.at = self.at.wrapping_add(1);
        n
    }
    fn position(&mut self, vertex: usize) -> Option<[f32; 3]> {
        (vertex < input(3) as usize).then(|| {
            [
                opaque_f32(vertex),
                opaque_f32(vertex + 1),
                opaque_f32(vertex + 2),
            ]
        })
    }
}

fn cluster_error(e: &ClusterError) {
    let mut sink = Sink {
        buf: [0; 160],
        len: 0,
    };
    let _ = black_box(write!(sink, "{e}"));
    black_box(&sink.buf);
}

fn run_cluster<I: Index, L: Index, const C: usize>() {
    let mut table = black_box(Clusterer::<C>::new());
    let mut quads = black_box(Quadrics::<C>::new());
    black_box((Clusterer::<C>::BYTES, Clusterer::<C>::BYTES_PER_CELL));
    let mut out: [[I; 3]; 64] = black_box([[I::ZERO; 3]; 64]);
    let mut src = Opaque { at: 0 };
    let grid = match input(5) & 3 {
        0 => GridChoice::CellSize(opaque_f32(6)),
        1 => GridChoice::Resolution(input(7)),
        _ => GridChoice::TargetTriangles(input(8) as usize),
    };
    let mut config = ClusterConfig::target(input(9) as usize);
    config.grid = grid;
    config.refine_passes = input(10);
    if input(11) & 1 == 0 {
        config = config.with_bbox(
            [opaque_f32(1), opaque_f32(2), opaque_f32(3)],
            [opaque_f32(4), opaque_f32(5), opaque_f32(6)],
        );
    }
    black_box(ClusterConfig::cell_size(opaque_f32(12)));
    let q = if input(12) & 1 == 0 {
        Some(&mut quads)
    } else {
        None
    };
    match table.cluster(
        &mut src,
        &config,
        &mut out,
        Scratch {
            quadrics: q,
            ..Scratch::new()
        },
    ) {
        Ok(r) => {
            black_box(r);
        }
        Err(e) => cluster_error(&e),
    }
    // With per-vertex memory: a bit or an 8-byte cache per vertex (any length).
    let mut bits: [u32; 4] = black_box([0; 4]);
    let mut cache: [u64; 24] = black_box([0; 24]);
    let (nb, nc) = (input(13) as usize, input(14) as usize);
    if let (Some(b), Some(c)) = (bits.get_mut(..nb), cache.get_mut(..nc)) {
        let q = if input(15) & 1 == 0 {
            Some(&mut quads)
        } else {
            None
        };
        match table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: q,
                seen: b,
                ..Scratch::new()
            },
        ) {
            Ok(r) => {
                black_box(r);
            }
            Err(e) => cluster_error(&e),
        }
        let q = if input(16) & 1 == 0 {
            Some(&mut quads)
        } else {
            None
        };
        match table.cluster(
            &mut src,
            &config,
            &mut out,
            Scratch {
                quadrics: q,
                cache: c,
                ..Scratch::new()
            },
        ) {
            Ok(r) => {
                black_box(r);
            }
            Err(e) => cluster_error(&e),
        }
        // And 32 bytes of keys per vertex (any length).
        let mut keys: [[u32; KEY_LANES]; 16] = black_box([[0; KEY_LANES]; 16]);
        let nk = input(17) as usize;
        if let Some(k) = keys.get_mut(..nk) {
            let q = if input(18) & 1 == 0 {
                Some(&mut quads)
            } else {
                None
            };
            match table.cluster(
                &mut src,
                &config,
                &mut out,
                Scratch {
                    quadrics: q,
                    cache: c,
                    keys: k,
                    ..Scratch::new()
                },
            ) {
                Ok(r) => {
                    black_box(r);
                }
                Err(e) => cluster_error(&e),
            }
        }
    }
    // A slice source, and the single-pass stream with an accessor.
    let positions: [[f32; 3]; 16] = black_box([[0.0; 3]; 16]);
    let tris: [[I; 3]; 16] = black_box([[I::ZERO; 3]; 16]);
    let (np, nt) = (input(3) as usize, input(4) as usize);
    let (Some(p), Some(t)) = (positions.get(..np), tris.get(..nt)) else {
        return;
    };
    let mut s = SliceSource::new(p, t);
    match table.cluster(&mut s, &config, &mut out, Scratch::new()) {
        Ok(r) => {
            black_box(r);
        }
        Err(e) => cluster_error(&e),
    }
    let g = Grid::with_cell_size(
        [opaque_f32(1), opaque_f32(2), opaque_f32(3)],
        [opaque_f32(4), opaque_f32(5), opaque_f32(6)],
        opaque_f32(7),
    );
    let g = match g {
        Ok(g) => g,
        Err(e) => {
            cluster_error(&e);
            match Grid::with_resolution([0.0; 3], [opaque_f32(8); 3], input(9)) {
                Ok(g) => g,
                Err(e) => return cluster_error(&e),
            }
        }
    };
    black_box((g.resolution(), g.key([opaque_f32(10), opaque_f32(11), 0.0])));
    let chunk: [[u32; 3]; 8] = black_box([[0; 3]; 8]);
    let mut acc = PositionFn(|v: usize| p.get(v).copied());
    match table.stream(g, &mut out) {
        Ok(mut st) => {
            let _ = st.push(chunk.get(..input(13) as usize).unwrap_or(&[]), &mut acc);
            let mut pp = p;
            let _ = st.push(&chunk, &mut pp);
            match st.finish() {
                Ok(r) => {
                    black_box(r);
                }
                Err(e) => cluster_error(&e),
            }
        }
        Err(e) => cluster_error(&e),
    }
    // Cluster, then collapse.
    let mut ws = black_box(Workspace::<L, 48, 64>::new());
    let mut vertices = [0u32; 48];
    let mut pos = [[0.0f32; 3]; 48];
    let ccfg = opaque_config();
    let scratch = Scratch {
        vertices: &mut vertices,
        positions: &mut pos,
        ..Scratch::new()
    };
    match cluster_then_collapse(
        &mut table,
        &mut src,
        &config,
        &ccfg,
        &mut out,
        ws.as_storage(),
        scratch,
    ) {
        Ok((c, r)) => {
            black_box(c);
            use_report(&r);
        }
        Err(ThenCollapseError::Cluster(e)) => cluster_error(&e),
        Err(ThenCollapseError::Collapse(e)) => display(&e),
    }
    black_box(&out);
}

#[cfg(feature = "defmt")]
mod log {
    /// A logger that drops everything (defmt needs one to link).
    #[defmt::global_logger]
    struct Null;

    // SAFETY: nothing is shared; every method does nothing.
    unsafe impl defmt::Logger for Null {
        fn acquire() {}
        unsafe fn flush() {}
        unsafe fn release() {}
        unsafe fn write(bytes: &[u8]) {
            core::hint::black_box(bytes);
        }
    }
}

/// The fast mode (`pipeline::FastWorkspace`) in arithmetic `N`: its one entry point on opaque
/// input (`position` opaque too).
fn run_fast<L: Index, I: Index, const V: usize, const T: usize, N: Arithmetic>(
    position: N::Position,
) {
    let mut ws = black_box(tinydecimate::pipeline::FastWorkspace::<L, V, T, N>::new());
    black_box(tinydecimate::pipeline::FastWorkspace::<L, V, T, N>::BYTES);
    let positions: [N::Position; V] = black_box([position; V]);
    let mut tris: [[I; 3]; T] = black_box([[I::ZERO; 3]; T]);
    let (np, nt) = (input(3) as usize, input(4) as usize);
    let (Some(p), Some(t)) = (positions.get(..np), tris.get_mut(..nt)) else {
        return;
    };
    match ws.simplify(p, t, &opaque_config()) {
        Ok(r) => use_report(&r),
        Err(e) => display(&e),
    }
    black_box(&tris);
    // With wedges: a welded mesh's entry point, the wedges as opaque as the triangles.
    let mut wedges: [[I; 3]; T] = black_box([[I::ZERO; 3]; T]);
    let nw = input(7) as usize;
    let (Some(t), Some(w)) = (tris.get_mut(..nt), wedges.get_mut(..nw)) else {
        return;
    };
    match ws.simplify_with_wedges(p, t, w, &opaque_config()) {
        Ok(r) => use_report(&r),
        Err(e) => display(&e),
    }
    black_box(&tris);
    black_box(&wedges);
}

/// The lean mode (`pipeline::LeanWorkspace`) in arithmetic `N`: its one entry point on opaque
/// input (`position` opaque too).
fn run_lean<L: Index, I: Index, const V: usize, const T: usize, N: Arithmetic>(
    position: N::Position,
) {
    let mut ws = black_box(tinydecimate::pipeline::LeanWorkspace::<L, V, T, N>::new());
    black_box(tinydecimate::pipeline::LeanWorkspace::<L, V, T, N>::BYTES);
    let positions: [N::Position; V] = black_box([position; V]);
    let mut tris: [[I; 3]; T] = black_box([[I::ZERO; 3]; T]);
    let (np, nt) = (input(3) as usize, input(4) as usize);
    let (Some(p), Some(t)) = (positions.get(..np), tris.get_mut(..nt)) else {
        return;
    };
    match ws.simplify(p, t, &opaque_config()) {
        Ok(r) => use_report(&r),
        Err(e) => display(&e),
    }
    black_box(&tris);
    // With wedges: a welded mesh's entry point, the wedges as opaque as the triangles.
    let mut wedges: [[I; 3]; T] = black_box([[I::ZERO; 3]; T]);
    let nw = input(7) as usize;
    let (Some(t), Some(w)) = (tris.get_mut(..nt), wedges.get_mut(..nw)) else {
        return;
    };
    match ws.simplify_with_wedges(p, t, w, &opaque_config()) {
        Ok(r) => use_report(&r),
        Err(e) => display(&e),
    }
    black_box(&tris);
    black_box(&wedges);
}

/// `pipeline::quantise` on opaque positions into an output of opaque length, and the grid it
/// returns.
fn run_quantise<const V: usize>() {
    let positions: [[f32; 3]; V] = black_box([[opaque_f32(5); 3]; V]);
    let mut grid: [[u16; 3]; V] = black_box([[0; 3]; V]);
    let (np, ng) = (input(3) as usize, input(4) as usize);
    let (Some(p), Some(g)) = (positions.get(..np), grid.get_mut(..ng)) else {
        return;
    };
    match quantise(p, g) {
        Ok(frame) => {
            black_box(frame.position([input(6) as u16; 3]));
            black_box(frame.error());
        }
        Err(e) => display(&e),
    }
    black_box(&grid);
}

#[entry]
fn main() -> ! {
    #[cfg(feature = "selftest")]
    black_box([1u8, 2, 3][input(0) as usize]);
    run::<u16, u16, 96, 160>();
    run::<u32, u32, 96, 160>();
    run::<u16, u32, 96, 160>();
    run::<u32, u16, 96, 160>();
    progressive::<u16, 48, 80>();
    progressive::<u32, 48, 80>();
    run_cluster::<u16, u16, 64>();
    run_cluster::<u32, u32, 64>();
    run_fast::<u16, u16, 96, 160, Float>([opaque_f32(5); 3]);
    run_fast::<u32, u32, 96, 160, Float>([opaque_f32(5); 3]);
    run_lean::<u16, u16, 96, 160, Float>([opaque_f32(5); 3]);
    run_lean::<u32, u32, 96, 160, Float>([opaque_f32(5); 3]);
    // The integer arithmetic: grid coordinates of any value (off the grid too).
    run_fast::<u16, u16, 96, 160, Integer>([input(5) as u16; 3]);
    run_fast::<u32, u32, 96, 160, Integer>([input(5) as u16; 3]);
    run_lean::<u16, u16, 96, 160, Integer>([input(5) as u16; 3]);
    run_lean::<u32, u32, 96, 160, Integer>([input(5) as u16; 3]);
    run_quantise::<96>();
    loop {
        black_box(());
    }
}

/// A placement from an opaque word.
fn placement_of(x: u32) -> Placement {
    if x & 1 == 0 {
        Placement::Subset
    } else {
        Placement::Optimal
    }
}

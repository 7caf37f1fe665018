//! Collapse costs: how much moving one vertex onto a neighbour changes the surface.
//!
//! The engine prices a vertex's collapses in one walk around its fan. Each triangle of the fan
//! is handed to [`Cost::add`] (its unit normal and twice its area), building a small summary
//! of the fan on the stack, then each candidate target is priced from that summary by
//! [`Cost::price`] in O(1). A cost that needs every surviving triangle's *new* normal (the
//! paper's W) says so with [`Cost::needs_turn`]; the engine then walks the fan once more per
//! candidate and passes the summed normal change. A new cost is one more implementation of this
//! trait, passed to [`Storage::start`](crate::Storage::start); the engine does not change.
//!
//! The built-in costs take their settings (boundary weight, schedule) from the [`Config`] when
//! the run starts ([`Cost::configure`]), so each setting is given once.
//!
//! All lengths are in the engine's normalised units (the input's bounding box mapped to about
//! `[-1, 1]³`), so costs do not depend on the scale of the input.

use crate::math::{self, V3};
use crate::quadric::{add, form, outer, solve, translate};
pub use crate::quadric::{error, VertexQuadric};
use crate::{Config, ConfigField, CostKind, Error};

/// `Error::InvalidConfig` for `field`.
fn bad(field: ConfigField) -> Result<(), Error> {
    Err(Error::InvalidConfig { field })
}

/// One candidate collapse `from -> to`, as a cost sees it.
#[derive(Clone, Copy, Debug)]
pub struct Move {
    /// How far the moving vertex moves (`to - from`).
    pub d: [f32; 3],
    /// For a boundary vertex moving along its boundary: squared distance from it to the new
    /// boundary edge, i.e. how far the boundary retreats. Zero otherwise.
    pub retreat2: f32,
    /// Σ ‖N_new − N_old‖² over the surviving triangles (unit normals; Lin 2007 eq. 2), when
    /// [`Cost::needs_turn`]; zero otherwise.
    pub turn: f32,
    /// The moving vertex (removed by the collapse).
    pub from: usize,
    /// The kept vertex.
    pub to: usize,
    /// Their positions (normalised units).
    pub p_from: V3,
    /// See `p_from`.
    pub p_to: V3,
    /// The kept vertex must stay where it is (it is a feature vertex, or positions are
    /// read-only): a placing cost prices the move at `p_to`.
    pub keep: bool,
}

/// A collapse cost. Lower is better; the engine never performs a collapse whose price is not
/// finite.
pub trait Cost {
    /// Called once when the run starts, after the configuration was validated, with the
    /// number of positions: takes the settings the cost needs from `config` and checks its
    /// own storage and the configuration it can run with ([`Error::Capacity`],
    /// [`Error::InvalidConfig`]). Accepts anything by default.
    fn configure(&mut self, _config: &Config, _vertices: usize) -> Result<(), Error> {
        Ok(())
    }
    /// Where the kept vertex goes ([`Placement::Optimal`] needs
    /// [`Positions::Write`](crate::Positions::Write) and no error bound). Subset by default.
    fn placement(&self) -> Placement {
        Placement::Subset
    }
    /// What the cost keeps of one fan while the engine walks it.
    type Fan: Copy;
    /// The summary of an empty fan.
    fn empty(&self) -> Self::Fan;
    /// Adds one triangle of the moving vertex's fan: its unit normal (zero if it has no area)
    /// and twice its area.
    fn add(&self, fan: &mut Self::Fan, normal: V3, area2: f32);
    /// The price of one move of the vertex whose fan was summarised.
    fn price(&self, fan: &Self::Fan, m: &Move) -> f32;
    /// Whether [`Move::turn`] must be computed (one more fan walk per candidate).
    fn needs_turn(&self) -> bool;
    /// Whether [`Cost::add`] and [`Cost::round`] use what they are given (the fan's normals
    /// and areas). `false` lets the engine skip a cross product and a 1/√ per triangle of
    /// every walk when the feature rule is off too. `true` by default.
    fn needs_fan(&self) -> bool {
        true
    }
    /// Called at the start of every round with the mean of twice the triangle area over the
    /// current mesh (the scale of its triangles). Nothing by default.
    fn round(&mut self, _mean_area2: f32) {}
    /// Whether the cost keeps state per vertex (stored quadrics). If so the engine, once before
    /// the first keys, hands it every used vertex's planes ([`Cost::plane`]); after each
    /// collapse it calls [`Cost::merge`]. Such a cost's price of `x -> y` must depend only on
    /// the two vertices' states and positions: without the feature rule the engine then
    /// re-keys a collapse's neighbours by their one changed price, onto the kept vertex.
    fn stores(&self) -> bool {
        false
    }
    /// Adds `weight · (n·x + d)²` to vertex `v`'s state (only if [`Cost::stores`]): the plane
    /// of one of its triangles (weight: twice its area), or a boundary plane. `x` is relative
    /// to `v`'s position (the engine passes planes through `v`, so `d` is zero): a cost may keep
    /// each vertex's state in a frame centred on it, which keeps `f32` sums of nearby planes
    /// free of the cancellation a global origin causes.
    fn plane(&mut self, _v: usize, _n: V3, _d: f32, _weight: f32) {}
    /// Adds the plane through one of `v`'s boundary edges, perpendicular to its triangle (Cheng,
    /// Pan and Shi 1998 §3.3); `weight` is the squared edge length, the cost applies its own
    /// factor.
    fn boundary_plane(&mut self, _v: usize, _n: V3, _d: f32, _weight: f32) {}
    /// Vertex `from` (at `p_from`) was collapsed onto `to` (at `p_to`), which is now at `p_new`
    /// (only if [`Cost::stores`]).
    fn merge(&mut self, _from: usize, _to: usize, _p_from: V3, _p_to: V3, _p_new: V3) {}
    /// Whether [`Cost::place`] may ever return a position. `false` (the default) lets the
    /// compiler drop the engine's placement paths from the image of a cost that never moves a
    /// vertex (the flash this saves is in docs/devices.md).
    const PLACES: bool = false;
    /// Where the kept vertex goes for this move, if it moves at all (optimal placement); the
    /// engine checks the legality rules there and writes it to the caller's mutable positions.
    /// `None` by default: the kept vertex stays (subset placement).
    fn place(&self, _m: &Move) -> Option<V3> {
        None
    }
}

/// Memoryless quadric error (Lindstrom and Turk's "memoryless" simplification, 1998; the
/// plane quadrics of Cheng, Pan and Shi 1998 §2.3 (their K_p and Q_s) and of an
/// implementation of Garland's edge collapse, without the per-vertex matrix): the area-weighted
/// squared distance from the kept vertex to the planes of the removed vertex's current triangles,
///
/// ```text
/// E(a -> b) = dᵀ Q d · (1 + Ā / A_fan),   Q = Σ_t A_t n_t n_tᵀ,   d = p_b − p_a
/// ```
///
/// plus `boundary_weight` times the squared boundary retreat times `Ā`. `Q` is six floats on
/// the stack, built in one fan walk; each candidate then costs a 3×3 quadratic form.
///
/// The factor `1 + Ā/A_fan` (Ā: the mean triangle area of the mesh at the start of the round,
/// A_fan: the fan's area) is what keeps thin parts: an area-weighted sum alone makes a fan of
/// small triangles cheap to remove however far it moves, so thin parts (the cow's teats and
/// tail) go first; dividing by the fan's area alone (a mean squared distance) keeps them but
/// raises the mean error on every shared mesh. The variants' figures, measured with
/// `host-sim bench`, are in docs/algorithm.md.
///
/// Needs [`Config::cost`] = [`CostKind::Quadric`]; the boundary weight is
/// [`Config::boundary_weight`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    /// Weight of the boundary retreat (set when the run starts).
    boundary_weight: f32,
    /// Twice the mean triangle area of the current mesh (set each round by the engine).
    reference: f32,
}

impl Quadric {
    /// The memoryless quadric (its settings come from the configuration).
    pub const fn new() -> Self {
        Quadric {
            boundary_weight: 1.0,
            reference: 0.0,
        }
    }
}

impl Default for Quadric {
    fn default() -> Self {
        Self::new()
    }
}

/// The fan summary of [`Quadric`]: `Q` (upper triangle, row by row) and twice the area.
#[derive(Clone, Copy, Debug, Default)]
pub struct QuadricFan {
    q: [f32; 6],
    area2: f32,
}

impl Cost for Quadric {
    type Fan = QuadricFan;

    fn configure(&mut self, config: &Config, _vertices: usize) -> Result<(), Error> {
        if config.cost != CostKind::Quadric {
            return bad(ConfigField::Cost);
        }
        self.boundary_weight = config.boundary_weight;
        Ok(())
    }

    fn empty(&self) -> QuadricFan {
        QuadricFan::default()
    }

    #[inline]
    fn add(&self, f: &mut QuadricFan, n: V3, area2: f32) {
        let w = area2;
        let q = &mut f.q;
        q[0] += w * n[0] * n[0];
        q[1] += w * n[0] * n[1];
        q[2] += w * n[0] * n[2];
        q[3] += w * n[1] * n[1];
        q[4] += w * n[1] * n[2];
        q[5] += w * n[2] * n[2];
        f.area2 += area2;
    }

    #[inline]
    fn price(&self, f: &QuadricFan, m: &Move) -> f32 {
        let (q, d) = (&f.q, &m.d);
        let e = q[0] * d[0] * d[0]
            + q[3] * d[1] * d[1]
            + q[5] * d[2] * d[2]
            + 2.0 * (q[1] * d[0] * d[1] + q[2] * d[0] * d[2] + q[4] * d[1] * d[2]);
        let e = if e > 0.0 { e } else { 0.0 };
        let thin = if f.area2 > 0.0 {
            1.0 + self.reference / f.area2
        } else {
            1.0
        };
        e * thin + self.boundary_weight * m.retreat2 * self.reference
    }

    fn needs_turn(&self) -> bool {
        false
    }

    fn round(&mut self, mean_area2: f32) {
        self.reference = mean_area2;
    }
}

/// Another name for [`Quadric`], the memoryless quadric.
#[deprecated(note = "use `Quadric`")]
pub type PlaneDistance = Quadric;

/// The paper's normal variation W (Lin 2007 §2, eq. 1-2, Algorithm 1): the sum over the moving
/// vertex's surviving triangles of ‖N_new − N_old‖², with no trigonometry.
///
/// Needs [`Config::cost`] = [`CostKind::NormalVariation`]; both settings come from the
/// configuration when the run starts:
///
/// * `length_weighted`: multiply by the squared edge length (the greedy schedule). W measures how
///   far normals turn, not how far the surface moves; as a *global* priority alone it prefers long
///   collapses across flat regions. Displacement is about length × normal change, so W·ℓ²
///   ranks collapses by a squared distance.
/// * `boundary_weight` ([`Config::boundary_weight`]): a boundary vertex moving along its boundary
///   adds `boundary_weight · retreat² / ℓ²` (scale-free like W; with W·ℓ², `boundary_weight ·
///   retreat²`), so open meshes keep their rims.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalVariation {
    /// Multiply by the squared edge length (greedy schedule).
    length_weighted: bool,
    /// Weight of the boundary retreat.
    boundary_weight: f32,
}

impl NormalVariation {
    /// The normal variation (its settings come from the configuration).
    pub const fn new() -> Self {
        NormalVariation {
            length_weighted: false,
            boundary_weight: 1.0,
        }
    }

    const fn of(config: &Config) -> Self {
        NormalVariation {
            length_weighted: matches!(config.schedule, crate::Schedule::Greedy),
            boundary_weight: config.boundary_weight,
        }
    }
}

impl Default for NormalVariation {
    fn default() -> Self {
        Self::new()
    }
}

impl Cost for NormalVariation {
    type Fan = ();

    fn configure(&mut self, config: &Config, _vertices: usize) -> Result<(), Error> {
        if config.cost != CostKind::NormalVariation {
            return bad(ConfigField::Cost);
        }
        *self = Self::of(config);
        Ok(())
    }

    fn empty(&self) {}

    #[inline]
    fn add(&self, _: &mut (), _: V3, _: f32) {}

    #[inline]
    fn price(&self, _: &(), m: &Move) -> f32 {
        let l2 = math::dot(m.d, m.d);
        if self.length_weighted {
            m.turn * l2 + self.boundary_weight * m.retreat2
        } else if l2 > 0.0 {
            m.turn + self.boundary_weight * m.retreat2 / l2
        } else {
            m.turn
        }
    }

    fn needs_turn(&self) -> bool {
        true
    }

    fn needs_fan(&self) -> bool {
        false
    }
}

/// The built-in costs, chosen at run time by [`Config::cost`] when the run starts (what
/// [`Storage::simplify`](crate::Storage::simplify) uses): one engine for both.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Builtin {
    /// [`Quadric`].
    Quadric(Quadric),
    /// [`NormalVariation`].
    NormalVariation(NormalVariation),
}

impl Builtin {
    /// The cost the configuration names when the run starts.
    pub const fn new() -> Self {
        Builtin::Quadric(Quadric::new())
    }

    /// The cost a configuration names (W is length-weighted under the greedy schedule).
    fn of(config: &Config) -> Self {
        match config.cost {
            CostKind::Quadric => Builtin::Quadric(Quadric {
                boundary_weight: config.boundary_weight,
                reference: 0.0,
            }),
            CostKind::NormalVariation => Builtin::NormalVariation(NormalVariation::of(config)),
        }
    }
}

impl Default for Builtin {
    fn default() -> Self {
        Self::new()
    }
}

impl Cost for Builtin {
    type Fan = QuadricFan;

    fn configure(&mut self, config: &Config, _vertices: usize) -> Result<(), Error> {
        *self = Self::of(config);
        Ok(())
    }

    fn empty(&self) -> QuadricFan {
        QuadricFan::default()
    }

    #[inline]
    fn add(&self, f: &mut QuadricFan, n: V3, area2: f32) {
        if let Builtin::Quadric(q) = self {
            q.add(f, n, area2)
        }
    }

    #[inline]
    fn price(&self, f: &QuadricFan, m: &Move) -> f32 {
        match self {
            Builtin::Quadric(q) => q.price(f, m),
            Builtin::NormalVariation(w) => w.price(&(), m),
        }
    }

    fn needs_turn(&self) -> bool {
        matches!(self, Builtin::NormalVariation(_))
    }

    fn needs_fan(&self) -> bool {
        matches!(self, Builtin::Quadric(_))
    }

    fn round(&mut self, mean_area2: f32) {
        if let Builtin::Quadric(q) = self {
            q.round(mean_area2)
        }
    }
}

/// Where a collapse with stored quadrics leaves the kept vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Placement {
    /// At one of the two endpoints (positions are only read, flash is fine).
    Subset,
    /// At the minimiser of Δ over the edge's summed quadric (Cheng, Pan and Shi 1998 §2.3, and
    /// Garland), written into the caller's mutable positions; the best of the endpoints and the
    /// midpoint when the 3×3 system is ill-conditioned or its solution lies far from the edge.
    Optimal,
}

/// Accumulated quadric error metric (Garland's, as Cheng, Pan and Shi 1998 use it, §2.3-2.5)
/// with per-vertex storage (`K_p = p pᵀ`, `Q_s` the sum over the vertex's triangles,
/// `Q = Q_s + Q_t` on a collapse, `Δ = vᵀ Q v` and an error-cost queue), as in an
/// implementation of Garland's edge collapse. Planes are area-weighted; a boundary vertex also
/// gets, for each boundary edge it is on, the plane through that edge perpendicular to its triangle
/// (Cheng, Pan and Shi 1998 §3.3), weighted by `boundary_weight` times the squared edge length.
///
/// The matrices live in a caller-provided slice, one [`VertexQuadric`] (40 bytes) per vertex, at
/// least as long as the positions (else [`Error::Capacity`] for
/// [`Capacity::Quadrics`](crate::Capacity::Quadrics) when the run starts). Needs the greedy
/// schedule (else [`Error::InvalidConfig`] for [`ConfigField::Schedule`]) and [`Config::cost`]
/// = [`CostKind::Quadric`]; the boundary weight is [`Config::boundary_weight`].
/// [`Config::stored`] is the recommended configuration (no feature rule: lower mean error,
/// and the faster re-keying). All in the engine's normalised units, and each vertex's
/// matrix in a frame centred on that vertex (moved to the kept vertex's new position on a
/// collapse): in `f32`, `vᵀQv` with a global origin loses the small errors of early collapses
/// to cancellation between terms of order one.
pub struct StoredQuadric<'q> {
    q: &'q mut [VertexQuadric],
    boundary_weight: f32,
    placement: Placement,
}

impl<'q> StoredQuadric<'q> {
    /// A stored quadric over `storage` (contents on entry do not matter: zeroed when the run
    /// starts; the engine fills it), leaving kept vertices where `placement` says.
    pub fn new(storage: &'q mut [VertexQuadric], placement: Placement) -> Self {
        StoredQuadric {
            q: storage,
            boundary_weight: 1.0,
            placement,
        }
    }

    /// The boundary-plane weight.
    pub fn boundary_weight(&self) -> f32 {
        self.boundary_weight
    }

    /// The placement.
    pub fn placement(&self) -> Placement {
        self.placement
    }

    /// Vertex `v`'s quadric (zero if out of range).
    pub fn quadric(&self, v: usize) -> VertexQuadric {
        self.q.get(v).copied().unwrap_or([0.0; 10])
    }

    /// The edge's quadric `Q_from + Q_to` in the frame centred on `p_to`.
    fn edge(&self, m: &Move) -> VertexQuadric {
        add(
            &translate(&self.quadric(m.from), math::sub(m.p_to, m.p_from)),
            &self.quadric(m.to),
        )
    }

    /// The best position for `m` relative to `p_to`, and its error: the solution of the 3×3 system
    /// if it is well conditioned and near the edge, else (and if better) an endpoint or the
    /// midpoint. Candidates are compared in a fixed order with `<`, so ties go to the earlier one.
    fn best(&self, m: &Move) -> (V3, f32) {
        if m.keep || self.placement == Placement::Subset {
            // At p_to, the edge's quadric is `Q_from` read at `p_to − p_from` plus `Q_to`'s
            // constant term (its own frame's origin): the same sum `edge` would form, bit for
            // bit, without building the 10-term matrix (a third of a subset run's pricing).
            let c = form(&self.quadric(m.from), math::sub(m.p_to, m.p_from))
                + self.q.get(m.to).map_or(0.0, |q| q[9]);
            return ([0.0; 3], if c > 0.0 { c } else { 0.0 });
        }
        let q = self.edge(m);
        // Relative to p_to: the kept end is 0, the removed one -d.
        let mut best = ([0.0; 3], error(&q, [0.0; 3]));
        {
            let back = math::scale(m.d, -1.0);
            let mid = math::scale(m.d, -0.5);
            let l2 = math::dot(m.d, m.d);
            if let Some(x) = solve(&q) {
                let off = math::sub(x, mid);
                if math::dot(off, off) <= l2 {
                    let c = error(&q, x);
                    if c < best.1 {
                        best = (x, c);
                    }
                }
            }
            for x in [back, mid] {
                let c = error(&q, x);
                if c < best.1 {
                    best = (x, c);
                }
            }
        }
        best
    }
}

impl Cost for StoredQuadric<'_> {
    type Fan = ();
    const PLACES: bool = true;

    fn configure(&mut self, config: &Config, vertices: usize) -> Result<(), Error> {
        if self.q.len() < vertices {
            return Err(Error::Capacity {
                what: crate::Capacity::Quadrics,
                needed: vertices,
                available: self.q.len(),
            });
        }
        if config.schedule != crate::Schedule::Greedy {
            return bad(ConfigField::Schedule);
        }
        if config.cost != CostKind::Quadric {
            return bad(ConfigField::Cost);
        }
        self.boundary_weight = config.boundary_weight;
        for q in self.q.iter_mut() {
            *q = [0.0; 10];
        }
        Ok(())
    }

    fn placement(&self) -> Placement {
        self.placement
    }

    fn empty(&self) {}

    #[inline]
    fn add(&self, _: &mut (), _: V3, _: f32) {}

    #[inline]
    fn price(&self, _: &(), m: &Move) -> f32 {
        self.best(m).1
    }

    fn needs_turn(&self) -> bool {
        false
    }

    fn needs_fan(&self) -> bool {
        false
    }

    fn stores(&self) -> bool {
        true
    }

    fn plane(&mut self, v: usize, n: V3, d: f32, w: f32) {
        if let Some(q) = self.q.get_mut(v) {
            for (q, k) in q.iter_mut().zip(outer(n, d)) {
                *q += w * k;
            }
        }
    }

    fn boundary_plane(&mut self, v: usize, n: V3, d: f32, w: f32) {
        self.plane(v, n, d, w * self.boundary_weight)
    }

    fn merge(&mut self, from: usize, to: usize, p_from: V3, p_to: V3, p_new: V3) {
        let s = add(
            &translate(&self.quadric(from), math::sub(p_new, p_from)),
            &translate(&self.quadric(to), math::sub(p_new, p_to)),
        );
        if let Some(q) = self.q.get_mut(to) {
            *q = s;
        }
    }

    fn place(&self, m: &Move) -> Option<V3> {
        if m.keep || self.placement == Placement::Subset {
            return None;
        }
        let x = self.best(m).0;
        if x == [0.0; 3] {
            // The kept end stays where it is.
            return None;
        }
        Some(math::add(m.p_to, x))
    }
}

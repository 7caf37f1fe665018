//! Hoppe's energy as a collapse cost, in fixed memory.

use super::{Cost, Move};
use crate::math::{self, V3};
use crate::{Config, Error};

/// Triangles of one fan the energy keeps ([`Energy`]'s [`Cost::corner`] ring): a vertex with
/// more is never moved (its price is infinite), as the engine prices only its first 32
/// neighbours anyway.
pub(crate) const RING: usize = 32;

/// The sample points one vertex carries, as their moments about the vertex's own position:
/// `[n, Σx, Σy, Σz, Σxx, Σxy, Σxz, Σyy, Σyz, Σzz]` (sample offsets `x − p_v`; `n` is a
/// weight, not a count: a triangle centroid is shared by its three corners). 40 bytes.
pub type Samples = [f32; 10];

/// Hoppe's energy `E = E_dist + E_spring` (Hoppe et al. 1993, Hoppe 1996; no `E_scalar`, and
/// `E_disc` on the boundary only), as a greedy collapse cost with subset placement. Cheng,
/// Pan and Shi 1998 cite it (their refs. 2-3, progressive meshes and mesh optimisation) as
/// the energy-optimisation way of building a progressive mesh (a point set `X` sampled from
/// the original surface, `E` from the distances of `X` to the simplified mesh), too slow for
/// them (their table 1), and use quadrics instead; the survey of simplification methods
/// among the project's reading writes the energy out:
///
/// ```text
/// E_dist = Σ_i d²(x_i, M),   E_spring = Σ_{edges (j,k)} κ ‖v_j − v_k‖²
/// ```
///
/// **Samples in fixed memory.** Each vertex carries the moments of the sample points merged
/// into it ([`Samples`], 40 bytes per vertex, in a caller slice): at the start its own
/// position (weight 1) and a third of each of its triangles' centroids (the centroids are
/// the error bound's control points, [`Controls`](crate::Controls)). A collapse `from -> to`
/// hands `from`'s samples to `to` ([`Cost::merge`], the moments moved to `to`'s frame).
///
/// **The price of `from -> to`** is the local energy after the move of what the move
/// changes:
///
/// ```text
/// E_dist   = tr(Q' M_from) / A'        Q' = Σ_t' A_t' n_t' n_t'ᵀ over the new triangles t'
/// E_disc   = w_b · n_from · r²          r: how far the boundary retreats (Move::retreat2)
/// E_spring = κ Σ ‖p_to − p_n‖²          over the edges the collapse creates
/// price    = E_dist + E_disc + E_spring
/// ```
///
/// `M_from` is the second moment of `from`'s samples about `p_to`, so `nᵀ M_from n` is the
/// sum of their squared distances to the plane through `p_to` with unit normal `n`, and
/// `E_dist` is that sum averaged over the planes of the triangles that replace `from`'s fan
/// (weighted by area, `A'` their total). `E_disc` stands in for the energy's discontinuity
/// term on the boundary only (the one discontinuity curve a mesh without attributes has): a
/// boundary vertex moving along its boundary prices all its samples (weight `n_from`) at the
/// boundary's retreat, times [`Config::boundary_weight`]; without it a flat border's samples
/// lie in every new plane and its corners would be cut for free.
///
/// **What is approximate.** The original projects each sample onto its nearest face; the
/// moments cannot say which face is nearest, so every sample is measured against every new
/// plane. On a crease this prices a move along the crease (samples of both sides against
/// planes of both sides) about as high as one across it, which is why the energy loses to the
/// quadric on the CAD meshes (docs/algorithm.md). A plane is nearer than its face, so
/// elsewhere `E_dist` can be below the original's; and the samples of `to` (whose own faces
/// the move changes too) are not counted.
///
/// The original ΔE subtracts the energy before the move: `from`'s samples against its current
/// fan and the springs of `from`'s edges. Both depend on `from` alone, not on `to`, so they
/// do not change which neighbour `from` moves onto; they are left out because the engine's
/// keys are non-negative (a negative price is clamped to zero, which would tie most
/// collapses: removing edges lowers `E_spring`). Across vertices the order differs: a vertex
/// with long edges gains nothing here for removing them.
///
/// **κ.** Hoppe 1996 lowers κ as the fit proceeds (a regulariser of his vertex
/// optimisation); with subset placement no vertex moves, and the spring only prefers targets
/// whose new edges are short (better-shaped triangles), and breaks the ties of flat regions,
/// where every move's `E_dist` is zero. `κ` is in units of sample weight: a created edge of
/// length ℓ costs as much as κ samples at distance ℓ from the new planes. A larger κ trades
/// distance for triangle shape; the default [`Energy::KAPPA`] = 0.01 keeps distance leading
/// and the spring as the tie-breaker (decision record: docs/algorithm.md; the
/// shape it buys on a flat grid: tests/energy.rs).
///
/// **Cost.** 40 bytes per vertex (the samples) instead of the memoryless quadric's none and
/// the stored quadric's 40; [`EnergyFan`] on the stack per walked fan (32 offsets,
/// about 400 bytes, against the quadric's 28). The spring and the new planes need `from`'s
/// neighbours, which a fan's normals and areas do not give: the engine hands each fan
/// triangle's two other corners ([`Cost::corner`]). Its price reads the fan, so every vertex
/// whose fan a collapse changed is re-keyed in full (the engine does so for a storing cost
/// with [`Cost::needs_fan`]). Each candidate costs one pass over the ring (a cross product
/// and a 1/√ per triangle) against the quadric's one 3×3 form (its instructions:
/// the `*-energy-*` cases of bench/DEVICES.md).
pub struct Energy<'s> {
    samples: &'s mut [Samples],
    /// Weight of `E_dist`.
    dist: f32,
    /// κ.
    spring: f32,
    /// [`Config::boundary_weight`] (set when the run starts).
    boundary: f32,
}

/// `from`'s fan as [`Energy`] keeps it: the offsets from `from` of each triangle's first
/// other corner in fan order, and the last triangle's second one (the ring).
#[derive(Clone, Copy, Debug)]
pub struct EnergyFan {
    x: [V3; RING],
    last: V3,
    n: usize,
    /// More than [`RING`] triangles.
    overflow: bool,
}

impl<'s> Energy<'s> {
    /// κ by default.
    pub const KAPPA: f32 = 0.01;

    /// The energy over `storage` (one [`Samples`] per vertex; contents on entry do not
    /// matter: set when the run starts), with weight 1 on `E_dist` and [`Energy::KAPPA`].
    pub fn new(storage: &'s mut [Samples]) -> Self {
        Energy {
            samples: storage,
            dist: 1.0,
            spring: Self::KAPPA,
            boundary: 1.0,
        }
    }

    /// With these weights on `E_dist` and `E_spring` (κ); zero switches a term off. Negative
    /// or non-finite weights are taken as zero.
    pub fn with_weights(mut self, dist: f32, spring: f32) -> Self {
        let ok = |w: f32| if w.is_finite() && w > 0.0 { w } else { 0.0 };
        self.dist = ok(dist);
        self.spring = ok(spring);
        self
    }

    /// Vertex `v`'s samples (zero if out of range).
    pub fn samples(&self, v: usize) -> Samples {
        self.samples.get(v).copied().unwrap_or([0.0; 10])
    }
}

/// `s`'s moments about a point `t` away from its frame's origin (`x − (p + t)`).
fn shift(s: &Samples, t: V3) -> Samples {
    let [n, sx, sy, sz, xx, xy, xz, yy, yz, zz] = *s;
    let [a, b, c] = t;
    // Σ (x − t)(x − t)ᵀ = M − s tᵀ − t sᵀ + n t tᵀ.
    [
        n,
        sx - n * a,
        sy - n * b,
        sz - n * c,
        xx - 2.0 * sx * a + n * a * a,
        xy - sx * b - sy * a + n * a * b,
        xz - sx * c - sz * a + n * a * c,
        yy - 2.0 * sy * b + n * b * b,
        yz - sy * c - sz * b + n * b * c,
        zz - 2.0 * sz * c + n * c * c,
    ]
}

/// Adds a sample of weight `w` at offset `x`.
fn sample(s: &mut Samples, x: V3, w: f32) {
    let [a, b, c] = x;
    for (m, v) in s
        .iter_mut()
        .zip([1.0, a, b, c, a * a, a * b, a * c, b * b, b * c, c * c])
    {
        *m += w * v;
    }
}

impl Cost for Energy<'_> {
    type Fan = EnergyFan;

    /// Checks the storage and sets every vertex's samples to its own position.
    fn configure(&mut self, config: &Config, vertices: usize) -> Result<(), Error> {
        if self.samples.len() < vertices {
            return Err(Error::Capacity {
                what: crate::Capacity::Quadrics,
                needed: vertices,
                available: self.samples.len(),
            });
        }
        if !config.schedule.is_ordered() {
            return super::bad(crate::ConfigField::Schedule);
        }
        for s in self.samples.iter_mut() {
            *s = [0.0; 10];
            s[0] = 1.0;
        }
        self.boundary = config.boundary_weight;
        Ok(())
    }

    fn empty(&self) -> EnergyFan {
        EnergyFan {
            x: [[0.0; 3]; RING],
            last: [0.0; 3],
            n: 0,
            overflow: false,
        }
    }

    #[inline]
    fn add(&self, _: &mut EnergyFan, _: V3, _: f32) {}

    #[inline]
    fn corner(&self, f: &mut EnergyFan, dx: V3, dy: V3) {
        match f.x.get_mut(f.n) {
            Some(x) => {
                *x = dx;
                f.n += 1;
            }
            None => f.overflow = true,
        }
        f.last = dy;
    }

    fn price(&self, f: &EnergyFan, m: &Move) -> f32 {
        match self.terms(f, m) {
            Some((dist, created)) => {
                let disc = self.boundary * m.retreat2 * self.samples(m.from)[0];
                self.dist * (dist + disc) + self.spring * created
            }
            None => f32::INFINITY,
        }
    }

    /// The mean squared distance of `from`'s samples to the new planes (`E_dist` over the
    /// samples' weight), plus the squared boundary retreat.
    fn error2(&self, f: &EnergyFan, m: &Move, _price: f32) -> f32 {
        let n = self.samples(m.from)[0];
        match self.terms(f, m) {
            Some((dist, _)) if n > 0.0 => dist / n + m.retreat2,
            _ => m.retreat2,
        }
    }

    fn needs_turn(&self) -> bool {
        false
    }

    fn stores(&self) -> bool {
        true
    }

    /// The samples of `v`'s triangles: a third of each centroid.
    fn triangle(&mut self, v: usize, _corners: [usize; 3], e1: V3, e2: V3) {
        if let Some(s) = self.samples.get_mut(v) {
            sample(s, math::scale(math::add(e1, e2), 1.0 / 3.0), 1.0 / 3.0);
        }
    }

    fn merge(&mut self, from: usize, to: usize, p_from: V3, p_to: V3, p_new: V3) {
        let a = shift(&self.samples(from), math::sub(p_new, p_from));
        let b = shift(&self.samples(to), math::sub(p_new, p_to));
        if let Some(s) = self.samples.get_mut(to) {
            for ((s, a), b) in s.iter_mut().zip(a).zip(b) {
                *s = a + b;
            }
        }
        if let Some(s) = self.samples.get_mut(from) {
            *s = [0.0; 10];
        }
    }

    /// `r2 · area2`, as the quadric costs price a part: its samples at about its
    /// radius from any plane.
    fn part(&self, r2: f32, area2: f32) -> f32 {
        super::quadric_part(r2, area2)
    }
}

impl Energy<'_> {
    /// `E_dist` and the created edges' Σ‖e‖² of `m` (unweighted); `None` for a fan of more
    /// than [`RING`] triangles.
    fn terms(&self, f: &EnergyFan, m: &Move) -> Option<(f32, f32)> {
        if f.overflow || f.n == 0 {
            return None;
        }
        let d = m.d;
        let ring = f.x.get(..f.n).unwrap_or(&[]);
        // An interior fan closes: its last corner is its first (the same subtraction, so
        // the same bits); a boundary fan has one more neighbour.
        let closed = ring.first() == Some(&f.last);
        let mut q = [0.0f32; 6];
        let mut area = 0.0;
        let mut created = 0.0;
        for (i, &x) in ring.iter().enumerate() {
            let y = ring.get(i + 1).copied().unwrap_or(f.last);
            let (ex, ey) = (math::sub(x, d), math::sub(y, d));
            if x != d {
                created += math::dot(ex, ex);
            }
            if x == d || y == d {
                // A triangle on the collapsed edge vanishes, and its third corner's edge
                // to `to` already exists: not created.
                let w = if x == d { ey } else { ex };
                created -= math::dot(w, w);
                continue;
            }
            let n = math::cross(ex, ey);
            let l2 = math::dot(n, n);
            if l2 > math::TINY2 && l2.is_finite() {
                // A n nᵀ = N Nᵀ / |N| with N twice the area times the unit normal.
                let r = math::rsqrt(l2);
                q[0] += n[0] * n[0] * r;
                q[1] += n[0] * n[1] * r;
                q[2] += n[0] * n[2] * r;
                q[3] += n[1] * n[1] * r;
                q[4] += n[1] * n[2] * r;
                q[5] += n[2] * n[2] * r;
                area += l2 * r;
            }
        }
        if !closed && f.last != d {
            let e = math::sub(f.last, d);
            created += math::dot(e, e);
        }
        let dist = if area > 0.0 {
            // `from`'s samples about `p_to`: their offsets less `d`.
            let s = shift(&self.samples(m.from), d);
            let t = q[0] * s[4]
                + q[3] * s[7]
                + q[5] * s[9]
                + 2.0 * (q[1] * s[5] + q[2] * s[6] + q[4] * s[8]);
            if t > 0.0 {
                t / area
            } else {
                0.0
            }
        } else {
            0.0
        };
        Some((dist, if created > 0.0 { created } else { 0.0 }))
    }
}

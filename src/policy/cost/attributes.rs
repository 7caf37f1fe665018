//! Stored quadrics with vertex attributes: the stored Garland quadric plus, per vertex, the
//! squared deviation of the caller's attributes (texture coordinates, normals, colours) from
//! their linear interpolation over the original triangles, as meshoptimizer's
//! `simplifyWithAttributes` adds it to its quadric (`quadricFromAttributes`, `QuadricGrad`,
//! the attribute `quadricError`).

use super::{bad, Cost, Move, Placement, StoredQuadric};
use crate::math::{self, V3};
use crate::quadric::{form, translate, VertexQuadric};
use crate::{Config, ConfigField, Error};

/// One vertex's attribute state for `N` attributes: `11 + 4·N` floats (`44 + 16·N` bytes: 76 B
/// for a UV pair, 92 B for a normal, 124 B for both), beside the vertex's 40-byte
/// [`VertexQuadric`].
///
/// For each triangle `t` of the vertex's fan and each attribute `k`, `e_tk(x) = g_tk·x +
/// h_tk` is the weighted attribute linearly interpolated over `t` (as a function of the
/// position `x` in the triangle's plane, extended along its normal), in a frame centred on the
/// vertex's position and on its own weighted attribute values. With `w_t` the triangle's
/// weight, `q` is `Σ_t w_t Σ_k (g_tk·x + h_tk)²` as a quadric (the layout of
/// [`VertexQuadric`]), `w` is `Σ_t w_t` and `g[k]` is `Σ_t w_t (g_tk, h_tk)`: the squared
/// deviation `Σ_t w_t Σ_k (e_tk(x) − α_k)²` of attribute values `α` at `x` is
/// `q(x) + Σ_k α_k (α_k w − 2 g[k](x))` (meshoptimizer's `quadricError` with gradients).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttributeState<const N: usize> {
    /// `Σ_t w_t Σ_k (g_tk·x + h_tk)²`, as a [`VertexQuadric`].
    pub q: VertexQuadric,
    /// `Σ_t w_t`.
    pub w: f32,
    /// `Σ_t w_t (g_tk, h_tk)` per attribute: the gradient and the value at the frame's origin.
    pub g: [[f32; 4]; N],
}

impl<const N: usize> AttributeState<N> {
    /// The state of no triangle.
    pub const ZERO: Self = AttributeState {
        q: [0.0; 10],
        w: 0.0,
        g: [[0.0; 4]; N],
    };

    /// `Σ_t w_t Σ_k (e_tk(x) − alpha_k)²` at `x` (in the state's frame), unclamped.
    pub fn error(&self, x: V3, alpha: &[f32; N]) -> f32 {
        let mut e = form(&self.q, x);
        for (a, g) in alpha.iter().zip(self.g.iter()) {
            let [gx, gy, gz, gw] = *g;
            e += a * (a * self.w - 2.0 * (gx * x[0] + gy * x[1] + gz * x[2] + gw));
        }
        e
    }

    /// The state in the frame centred on position `s` and attribute values `delta` (both
    /// relative to the current frame's origin): `x = x' + s` and every `e' = e − delta`.
    pub fn shifted(&self, s: V3, delta: &[f32; N]) -> Self {
        let mut out = *self;
        out.q = translate(&self.q, s);
        for g in out.g.iter_mut() {
            g[3] += g[0] * s[0] + g[1] * s[1] + g[2] * s[2];
        }
        // (e − δ)²: b' = b − Σ δ_k g_k, c' = c − 2 Σ δ_k h_k + w Σ δ_k².
        for (d, g) in delta.iter().zip(out.g.iter_mut()) {
            out.q[3] -= d * g[0];
            out.q[6] -= d * g[1];
            out.q[8] -= d * g[2];
            out.q[9] += d * (d * self.w - 2.0 * g[3]);
            g[3] -= d * self.w;
        }
        out
    }

    /// Element-wise sum.
    pub fn add(&self, o: &Self) -> Self {
        let mut s = *self;
        for (a, b) in s.q.iter_mut().zip(o.q.iter()) {
            *a += b;
        }
        s.w += o.w;
        for (a, b) in s.g.iter_mut().zip(o.g.iter()) {
            for (a, b) in a.iter_mut().zip(b.iter()) {
                *a += b;
            }
        }
        s
    }

    /// Adds the triangle spanned by the frame's origin and `e1`, `e2` (positions relative to
    /// it) with weighted attribute differences `d1`, `d2` at those corners (relative to the
    /// origin's), weighted by its squared doubled area `|e1 × e2|²`. A triangle without area
    /// adds nothing.
    ///
    /// The gradient `g_k` lies in the triangle's plane and meets `g_k·e1 = d1_k`,
    /// `g_k·e2 = d2_k` (meshoptimizer's barycentric form); the value at the origin is zero, so
    /// only `A`, `w` and the gradients grow. With the weight equal to the Gram determinant
    /// `|e1|²|e2|² − (e1·e2)²`, `w·g_k` needs no division.
    pub fn add_triangle(&mut self, e1: V3, e2: V3, d1: &[f32; N], d2: &[f32; N]) {
        let (d00, d01, d11) = (math::dot(e1, e1), math::dot(e1, e2), math::dot(e2, e2));
        let w = d00 * d11 - d01 * d01;
        if !(w > math::TINY2 && w.is_finite()) {
            return;
        }
        // w·g = (d11 e1 − d01 e2) d1 + (d00 e2 − d01 e1) d2.
        let u1 = math::sub(math::scale(e1, d11), math::scale(e2, d01));
        let u2 = math::sub(math::scale(e2, d00), math::scale(e1, d01));
        let inv = 1.0 / w;
        self.w += w;
        for ((a, b), g) in d1.iter().zip(d2.iter()).zip(self.g.iter_mut()) {
            let h = math::add(math::scale(u1, *a), math::scale(u2, *b));
            g[0] += h[0];
            g[1] += h[1];
            g[2] += h[2];
            // w g gᵀ = h hᵀ / w.
            let [x, y, z] = math::scale(h, inv);
            self.q[0] += h[0] * x;
            self.q[1] += h[0] * y;
            self.q[2] += h[0] * z;
            self.q[4] += h[1] * y;
            self.q[5] += h[1] * z;
            self.q[7] += h[2] * z;
        }
    }
}

/// [`StoredQuadric`] plus an attribute term: the price of a collapse `from -> to` is the
/// stored quadric's plus the squared deviation of `to`'s (weighted) attributes from the
/// attributes interpolated over every original triangle merged into `from`, at `to`'s position
/// ([`AttributeState`]). This is meshoptimizer's `simplifyWithAttributes` metric with subset
/// placement, in fixed memory.
///
/// **Attributes.** One `[f32; N]` per position (the slice must be at least as long as the
/// positions), read only: texture coordinates (`N = 2`), a normal (`N = 3`), both (`N = 5`),
/// colours; a non-finite value makes the collapses its triangles price non-finite, so they
/// are never made. Attribute `k` is multiplied by `weights[k]` (zero switches it off); as in
/// meshoptimizer, a weighted change of 1 across a triangle of size `d` is priced about like
/// moving it by `d`: each triangle's squared deviation is weighted by its squared doubled area
/// (length⁴, as the plane terms' `area · distance²`), in the engine's normalised units. The
/// weights are scale-free: the same weight means the same on a mesh of any size.
///
/// **Memory.** Two caller slices, one entry per position: the [`VertexQuadric`]s (40 B) and the
/// [`AttributeState`]s (`44 + 16·N` B): 116 B per vertex for UVs, 164 B for UVs and normals. A
/// short slice is [`Error::Capacity`] for [`Capacity::Quadrics`](crate::Capacity::Quadrics)
/// when the run starts, as is a short attribute slice.
///
/// **Placement.** Subset only: the kept vertex stays, with its own attributes, so a collapse
/// never invents an attribute value. [`Placement::Optimal`] is refused with
/// [`Error::InvalidConfig`] for [`ConfigField::Placement`].
///
/// **Seams.** One attribute state per engine vertex. Where vertices at one position are
/// welded (`seam::weld`, crate feature `seams`), the engine vertex is the position's
/// representative: each triangle's gradient is taken from its own wedges
/// ([`Cost::triangle`]), but only the triangles whose wedge at the position carries the
/// representative's attributes enter its state (the far side of a UV seam is not measured),
/// and a collapse is priced against the representatives' attributes (moving onto a seam
/// vertex from the far side of its representative's chart is priced with the seam's jump,
/// so it is dear). meshoptimizer keeps a state per wedge and prices each wedge against the
/// wedge it goes to. With split seams every vertex has exactly its own attributes and this
/// is meshoptimizer's metric for the seamless case.
///
/// **Error limit.** [`Config::error_limit`](crate::Config::error_limit) and the reported
/// errors stay geometric: [`Cost::error2`] is the stored quadric's alone.
pub struct AttributeQuadric<'q, 'a, const N: usize> {
    geometry: StoredQuadric<'q>,
    state: &'q mut [AttributeState<N>],
    attributes: &'a [[f32; N]],
    weights: [f32; N],
}

impl<'q, 'a, const N: usize> AttributeQuadric<'q, 'a, N> {
    /// The cost over `quadrics` and `state` (contents on entry do not matter: zeroed when the
    /// run starts), for `attributes` (one per position) weighted by `weights`.
    pub fn new(
        quadrics: &'q mut [VertexQuadric],
        state: &'q mut [AttributeState<N>],
        attributes: &'a [[f32; N]],
        weights: [f32; N],
    ) -> Self {
        AttributeQuadric {
            geometry: StoredQuadric::new(quadrics, Placement::Subset),
            state,
            attributes,
            weights,
        }
    }

    /// This cost with `placement`: [`Placement::Subset`] is accepted, [`Placement::Optimal`]
    /// refused with [`Error::InvalidConfig`] for [`ConfigField::Placement`] (attributes are
    /// not interpolated at a new position).
    pub fn with_placement(self, placement: Placement) -> Result<Self, Error> {
        match placement {
            Placement::Subset => Ok(self),
            Placement::Optimal => Err(Error::InvalidConfig {
                field: ConfigField::Placement,
            }),
        }
    }

    /// The geometric part.
    pub fn geometry(&self) -> &StoredQuadric<'q> {
        &self.geometry
    }

    /// Vertex `v`'s attribute state (zero if out of range).
    pub fn state(&self, v: usize) -> AttributeState<N> {
        self.state.get(v).copied().unwrap_or(AttributeState::ZERO)
    }

    /// Vertex `v`'s weighted attributes (zero if out of range).
    fn weighted(&self, v: usize) -> [f32; N] {
        let a = self.attributes.get(v).copied().unwrap_or([0.0; N]);
        let mut out = [0.0; N];
        for ((o, a), w) in out.iter_mut().zip(a.iter()).zip(self.weights.iter()) {
            *o = a * w;
        }
        out
    }

    /// `weighted(to) − weighted(from)`.
    fn delta(&self, from: usize, to: usize) -> [f32; N] {
        let (f, t) = (self.weighted(from), self.weighted(to));
        let mut d = [0.0; N];
        for ((d, f), t) in d.iter_mut().zip(f.iter()).zip(t.iter()) {
            *d = t - f;
        }
        d
    }

    /// The attribute term of `m`: `from`'s attribute quadric at `to`'s position and attributes.
    fn attribute_price(&self, m: &Move) -> f32 {
        let e = self
            .state(m.from)
            .error(math::sub(m.p_to, m.p_from), &self.delta(m.from, m.to));
        if e > 0.0 {
            e
        } else {
            0.0
        }
    }
}

impl<const N: usize> Cost for AttributeQuadric<'_, '_, N> {
    type Fan = ();

    fn configure(&mut self, config: &Config, vertices: usize) -> Result<(), Error> {
        self.geometry.configure(config, vertices)?;
        let short = self.state.len().min(self.attributes.len());
        if short < vertices {
            return Err(Error::Capacity {
                what: crate::Capacity::Quadrics,
                needed: vertices,
                available: short,
            });
        }
        if self.weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return bad(ConfigField::Cost);
        }
        for s in self.state.iter_mut() {
            *s = AttributeState::ZERO;
        }
        Ok(())
    }

    fn empty(&self) {}

    #[inline]
    fn add(&self, _: &mut (), _: V3, _: f32) {}

    fn price(&self, f: &(), m: &Move) -> f32 {
        self.geometry.price(f, m) + self.attribute_price(m)
    }

    /// The stored quadric's error alone (the limit is geometric).
    fn error2(&self, f: &(), m: &Move, _price: f32) -> f32 {
        let geometric = self.geometry.price(f, m);
        self.geometry.error2(f, m, geometric)
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
        self.geometry.plane(v, n, d, w)
    }

    fn boundary_plane(&mut self, v: usize, n: V3, d: f32, w: f32) {
        self.geometry.boundary_plane(v, n, d, w)
    }

    /// The triangle's gradient from its own corners' attributes (its wedges when seams are
    /// welded); a triangle whose corner at `v` carries other attributes than `v` (the far
    /// side of a seam through the representative `v`) is left out.
    fn triangle(&mut self, v: usize, corners: [usize; 3], e1: V3, e2: V3) {
        let [c0, c1, c2] = corners;
        if c0 != v && self.weighted(c0) != self.weighted(v) {
            return;
        }
        let d1 = self.delta(c0, c1);
        let d2 = self.delta(c0, c2);
        if let Some(s) = self.state.get_mut(v) {
            s.add_triangle(e1, e2, &d1, &d2);
        }
    }

    fn merge(&mut self, from: usize, to: usize, p_from: V3, p_to: V3, p_new: V3) {
        self.geometry.merge(from, to, p_from, p_to, p_new);
        // Subset placement: `to` stays at `p_to` with its own attributes.
        let moved = self
            .state(from)
            .shifted(math::sub(p_to, p_from), &self.delta(from, to));
        if let Some(s) = self.state.get_mut(to) {
            *s = s.add(&moved);
        }
    }

    fn part(&self, r2: f32, area2: f32) -> f32 {
        super::quadric_part(r2, area2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The triangle's interpolated attribute is reproduced: zero deviation at its own corners,
    /// the squared gap elsewhere.
    #[test]
    fn one_triangle_interpolates() {
        let mut s = AttributeState::<2>::ZERO;
        let (e1, e2) = ([1.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        let (d1, d2) = ([0.5, 0.0], [0.0, 3.0]);
        s.add_triangle(e1, e2, &d1, &d2);
        let w = 4.0; // |e1 × e2|²
        assert_eq!(s.w, w);
        assert!(s.error([0.0; 3], &[0.0, 0.0]).abs() < 1e-6);
        assert!(s.error(e1, &d1).abs() < 1e-5);
        assert!(s.error(e2, &d2).abs() < 1e-5);
        // At e1 with the origin's values: the gap is d1, squared, times w.
        let e = s.error(e1, &[0.0, 0.0]);
        assert!((e - w * 0.25).abs() < 1e-5, "{e}");
        // Along the normal the interpolation does not change.
        assert!(s.error([0.0, 0.0, 5.0], &[0.0, 0.0]).abs() < 1e-5);
        // Midpoint of e1-e2 with the mean value: on the plane, zero.
        let mid = [0.5, 1.0, 0.0];
        assert!(s.error(mid, &[0.25, 1.5]).abs() < 1e-5);
    }

    /// Shifting the frame changes nothing but the frame: the error at a point and value is the
    /// same before and after.
    #[test]
    fn shift_keeps_the_error() {
        let mut s = AttributeState::<2>::ZERO;
        s.add_triangle([1.0, 0.2, 0.0], [0.1, 1.0, 0.3], &[0.3, -0.2], &[0.1, 0.4]);
        s.add_triangle([0.1, 1.0, 0.3], [-1.0, 0.5, 0.0], &[0.1, 0.4], &[-0.2, 0.0]);
        let (sh, de) = ([0.3, -0.1, 0.2], [0.05, -0.1]);
        let t = s.shifted(sh, &de);
        for (x, a) in [
            ([0.2, 0.1, -0.3], [0.2, 0.1]),
            ([0.0, 0.0, 0.0], [0.0, 0.0]),
            ([-0.5, 0.7, 0.1], [-0.3, 0.6]),
        ] {
            let before = s.error(math::add(x, sh), &[a[0] + de[0], a[1] + de[1]]);
            let after = t.error(x, &a);
            assert!((before - after).abs() < 1e-5, "{before} {after}");
        }
    }

    /// The sum of two states is the sum of their errors.
    #[test]
    fn sum_adds_errors() {
        let mut a = AttributeState::<1>::ZERO;
        let mut b = AttributeState::<1>::ZERO;
        a.add_triangle([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], &[1.0], &[0.0]);
        b.add_triangle([0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], &[0.0], &[2.0]);
        let x = [0.3, 0.4, 0.1];
        let s = a.add(&b);
        let e = s.error(x, &[0.5]);
        assert!((e - a.error(x, &[0.5]) - b.error(x, &[0.5])).abs() < 1e-5);
    }

    /// The bytes per vertex the rustdoc states.
    #[test]
    fn state_sizes() {
        assert_eq!(core::mem::size_of::<AttributeState<2>>(), 76);
        assert_eq!(core::mem::size_of::<AttributeState<3>>(), 92);
        assert_eq!(core::mem::size_of::<AttributeState<5>>(), 124);
    }

    /// A triangle without area adds nothing.
    #[test]
    fn degenerate_triangle_is_skipped() {
        let mut s = AttributeState::<2>::ZERO;
        s.add_triangle([1.0, 0.0, 0.0], [2.0, 0.0, 0.0], &[1.0, 1.0], &[2.0, 2.0]);
        assert_eq!(s, AttributeState::ZERO);
    }
}

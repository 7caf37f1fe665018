//! A guaranteed error bound: control points (Zhu, Wang and Meng 2007, §2-§4).
//!
//! *Control points of the first kind* are the centroids of the **original** triangles (§2,
//! fig. 1); those of the *second kind* are the vertices of original feature edges (§2, fig. 2:
//! two triangles whose normals differ by more than an angle, here
//! [`Config::control_angle_deg`](crate::Config::control_angle_deg); boundary and non-manifold
//! edges count as feature edges too). Every control point belongs to one live triangle of the
//! current mesh, its *controlled triangle*, and its error is its distance to that triangle.
//!
//! Before a collapse `a -> b` the engine hands the bound the fan after it: every control point
//! of `a`'s triangles (those that disappear and those that change) must lie within `d_hold`
//! ([`Config::max_error`](crate::Config::max_error)) of some triangle of `b`'s new fan, or the
//! collapse is refused with [`Reject::Bound`](crate::Reject::Bound) (§3, steps 6-8). After the
//! collapse those control points go to their nearest triangle of the new fan (§3). Triangles
//! that do not touch `a` do not move (subset placement), so no other control point's distance
//! changes: the bound holds for every control point after every collapse, by induction.
//!
//! Storage: the controlled triangles are kept as one singly linked list per triangle slot, in
//! a caller-provided slice of links ([`control_len`]): a head per triangle slot and a next
//! link per control point (one per triangle and one per vertex), `2·T + V` links, 5 bytes per
//! triangle with `u16` links and the usual `V ≈ T/2` (10 with `u32`). The original triangles
//! are read from a second, read-only slice (it may stay in flash); control-point positions are
//! recomputed from it and the positions whenever they are needed, never stored.

use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::{next3, prev3, Mesh, NIL};

/// Links a bound needs for a mesh of `triangles` triangles and `vertices` positions: one head
/// per triangle slot and one next link per control point (a centroid per triangle, a feature
/// vertex per position).
pub const fn control_len(triangles: usize, vertices: usize) -> usize {
    triangles.saturating_mul(2).saturating_add(vertices)
}

/// A bound's original triangles against the ones to simplify: equal, else
/// [`Error::OriginalMismatch`](crate::Error::OriginalMismatch) at the first that differs.
pub(crate) fn same_triangles<I: Index>(
    original: &[[I; 3]],
    triangles: &[[I; 3]],
) -> Result<(), crate::Error> {
    match crate::tri::first_difference(original, triangles) {
        Some(triangle) => Err(crate::Error::OriginalMismatch { triangle }),
        None => Ok(()),
    }
}

/// The length of the bounding-box diagonal of `positions` (the finite ones), for a bound given
/// as a fraction of it ([`Config::with_relative_max_error`](crate::Config::with_relative_max_error)).
pub fn bounding_diagonal(positions: &[[f32; 3]]) -> f32 {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in positions {
        if p[0].is_finite() && p[1].is_finite() && p[2].is_finite() {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    if lo[0] > hi[0] {
        return 0.0;
    }
    // Halves, so that `hi - lo` cannot overflow; scaled back by 2 at the end.
    let d = [
        hi[0] * 0.5 - lo[0] * 0.5,
        hi[1] * 0.5 - lo[1] * 0.5,
        hi[2] * 0.5 - lo[2] * 0.5,
    ];
    let m = math::max_abs(d);
    if !(m > 0.0 && m.is_finite()) {
        return 0.0;
    }
    let u = math::scale(d, 1.0 / m);
    let l2 = math::dot(u, u);
    // One more Newton step than the backend's 1/√ (micromath's alone is ~1e-4 off): the bound
    // a caller asks for as a fraction should be that fraction to f32 precision.
    2.0 * m * sqrt(l2)
}

/// `√x` for reported distances: the backend's `1/√` and one more Newton step (micromath's
/// alone is about 1e-3 off), 0 for tiny or non-finite `x`. The veto itself compares squares.
pub(crate) fn sqrt(x: f32) -> f32 {
    if x > math::TINY2 && x.is_finite() {
        let r = math::rsqrt(x);
        x * (r * (1.5 - 0.5 * x * r * r))
    } else {
        0.0
    }
}

/// Squared distance from `p` to the triangle `t` (closest point by Voronoi regions, after
/// Ericson, "Real-Time Collision Detection" §5.1.5). A degenerate triangle falls back to its
/// edges.
pub(crate) fn point_triangle_distance2(p: V3, t: [V3; 3]) -> f32 {
    let [a, b, c] = t;
    let ab = math::sub(b, a);
    let ac = math::sub(c, a);
    let ap = math::sub(p, a);
    let d1 = math::dot(ab, ap);
    let d2 = math::dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return math::dot(ap, ap);
    }
    let bp = math::sub(p, b);
    let d3 = math::dot(ab, bp);
    let d4 = math::dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return math::dot(bp, bp);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return math::segment_distance2(p, a, b);
    }
    let cp = math::sub(p, c);
    let d5 = math::dot(ab, cp);
    let d6 = math::dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return math::dot(cp, cp);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return math::segment_distance2(p, a, c);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return math::segment_distance2(p, b, c);
    }
    let denom = va + vb + vc;
    let inside = if denom > 0.0 {
        let v = vb / denom;
        let w = vc / denom;
        let q = math::add(a, math::add(math::scale(ab, v), math::scale(ac, w)));
        let d = math::sub(p, q);
        math::dot(d, d)
    } else {
        f32::NAN
    };
    if inside.is_finite() {
        inside
    } else {
        let e = [
            math::segment_distance2(p, a, b),
            math::segment_distance2(p, b, c),
            math::segment_distance2(p, c, a),
        ];
        e[0].min(e[1]).min(e[2])
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::NoBound {}
    impl<I: crate::Index, K: crate::Index> Sealed for super::Controls<'_, I, K> {}
    impl<I: crate::Index, K: crate::Index> Sealed for super::Envelope<'_, I, K> {}
}

pub use super::envelope::{index_len, Envelope};

/// What the engine checks operations against: [`NoBound`] (the default, which costs nothing),
/// [`Controls`] or [`Envelope`]. Sealed.
pub trait Bound<'a, I: Index>: sealed::Sealed + 'a {
    /// The link type of the control slice.
    #[doc(hidden)]
    type K: Index;
    /// Whether there is a bound at all (a constant, so an unbounded engine has no trace of it).
    #[doc(hidden)]
    const ON: bool;
    /// The control points, if any.
    #[doc(hidden)]
    fn controls(&self) -> Option<&Controls<'a, I, Self::K>>;
    /// The control points, if any.
    #[doc(hidden)]
    fn controls_mut(&mut self) -> Option<&mut Controls<'a, I, Self::K>>;
    /// Whether the bound can judge a vertex removal's fill (so runs with
    /// [`VertexDecimation`](crate::VertexDecimation)).
    #[doc(hidden)]
    const FILLS: bool = false;
    /// The envelope, if any.
    #[doc(hidden)]
    #[inline(always)]
    fn envelope(&self) -> Option<&Envelope<'a, I, Self::K>> {
        None
    }
    /// The envelope, if any.
    #[doc(hidden)]
    #[inline(always)]
    fn envelope_mut(&mut self) -> Option<&mut Envelope<'a, I, Self::K>> {
        None
    }
    /// Checks the bound's storage and configuration when the run starts, before anything is
    /// written: `triangles` are the ones to simplify, `vertices` the number of positions.
    #[doc(hidden)]
    fn prepare(
        &mut self,
        triangles: &[[I; 3]],
        vertices: usize,
        config: &crate::Config,
    ) -> Result<(), crate::Error>;
}

impl<'a, I: Index, K: Index> Bound<'a, I> for Envelope<'a, I, K> {
    type K = K;
    const ON: bool = true;
    const FILLS: bool = true;
    #[inline(always)]
    fn controls(&self) -> Option<&Controls<'a, I, K>> {
        None
    }
    #[inline(always)]
    fn controls_mut(&mut self) -> Option<&mut Controls<'a, I, K>> {
        None
    }
    #[inline(always)]
    fn envelope(&self) -> Option<&Envelope<'a, I, K>> {
        Some(self)
    }
    #[inline(always)]
    fn envelope_mut(&mut self) -> Option<&mut Envelope<'a, I, K>> {
        Some(self)
    }
    fn prepare(
        &mut self,
        triangles: &[[I; 3]],
        vertices: usize,
        config: &crate::Config,
    ) -> Result<(), crate::Error> {
        Envelope::prepare(self, triangles, vertices, config)
    }
}

/// No error bound (the default engine): [`Config::max_error`](crate::Config::max_error) must
/// be infinite, else [`Error::InvalidConfig`](crate::Error::InvalidConfig) for
/// [`ConfigField::MaxError`](crate::ConfigField::MaxError) (a bound needs [`Controls`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoBound;

impl<'a, I: Index> Bound<'a, I> for NoBound {
    type K = u32;
    const ON: bool = false;
    #[inline(always)]
    fn controls(&self) -> Option<&Controls<'a, I, u32>> {
        None
    }
    #[inline(always)]
    fn controls_mut(&mut self) -> Option<&mut Controls<'a, I, u32>> {
        None
    }
    fn prepare(
        &mut self,
        _: &[[I; 3]],
        _: usize,
        config: &crate::Config,
    ) -> Result<(), crate::Error> {
        if config.max_error < f32::INFINITY {
            return Err(crate::Error::InvalidConfig {
                field: crate::ConfigField::MaxError,
            });
        }
        Ok(())
    }
}

impl<'a, I: Index, K: Index> Bound<'a, I> for Controls<'a, I, K> {
    type K = K;
    const ON: bool = true;
    #[inline(always)]
    fn controls(&self) -> Option<&Controls<'a, I, K>> {
        Some(self)
    }
    #[inline(always)]
    fn controls_mut(&mut self) -> Option<&mut Controls<'a, I, K>> {
        Some(self)
    }
    fn prepare(
        &mut self,
        triangles: &[[I; 3]],
        vertices: usize,
        config: &crate::Config,
    ) -> Result<(), crate::Error> {
        use crate::{Capacity, Error};
        same_triangles(self.original, triangles)?;
        let need = control_len(triangles.len(), vertices);
        let available = if need > K::COUNT {
            K::COUNT
        } else {
            self.links.len()
        };
        if need > available {
            return Err(Error::Capacity {
                what: Capacity::Controls,
                needed: need,
                available,
            });
        }
        let links = core::mem::take(&mut self.links);
        self.links = links.get_mut(..need).unwrap_or(&mut []);
        self.cos_feature = math::cos_deg(config.control_angle_deg);
        Ok(())
    }
}

/// The guaranteed error bound [`Config::max_error`](crate::Config::max_error) of a run (see the
/// module documentation), given to [`Storage::start`](crate::Storage::start): the original
/// triangles (read only, they may stay in flash) and the caller's link slice.
///
/// Checked when the run starts: `original` must equal the triangles to simplify
/// ([`Error::OriginalMismatch`](crate::Error::OriginalMismatch)); `links` must hold at least
/// [`control_len`]`(triangles, positions)` links of any [`Index`] type (`2·T + V`: 5 bytes
/// per triangle with `u16` and `V ≈ T/2`), all numbered below its `NIL`, else
/// [`Error::Capacity`](crate::Error::Capacity) for
/// [`Capacity::Controls`](crate::Capacity::Controls). The links are meaningless after
/// [`Simplifier::finish`](crate::Simplifier::finish) (the triangles are compacted). Positions
/// are only read (subset placement). An infinite `max_error` runs unbounded but still reports
/// E_max and E_mean.
pub struct Controls<'a, I: Index, K: Index> {
    original: &'a [[I; 3]],
    /// `[0, nt)`: first control point of each triangle slot; `[nt, 2·nt + nv)`: the next
    /// control point after each one. `K::NIL`: none.
    links: &'a mut [K],
    nt: usize,
    /// `d_hold²` in the mesh's normalised units.
    limit2: f32,
    /// Cosine of the feature-edge angle.
    cos_feature: f32,
}

impl<'a, I: Index, K: Index> Controls<'a, I, K> {
    /// Control points over the `original` triangles, linked in `links` (contents on entry do
    /// not matter); both are checked when the run starts.
    pub fn new(original: &'a [[I; 3]], links: &'a mut [K]) -> Self {
        Controls {
            original,
            nt: original.len(),
            links,
            limit2: f32::INFINITY,
            cos_feature: 1.0,
        }
    }

    #[inline]
    fn link(&self, i: usize) -> usize {
        match self.links.get(i) {
            Some(&k) if k != K::NIL => k.to_usize(),
            _ => NIL,
        }
    }

    #[inline]
    fn set_link(&mut self, i: usize, v: usize) {
        if let Some(k) = self.links.get_mut(i) {
            *k = if v == NIL { K::NIL } else { K::narrow(v) };
        }
    }

    #[inline]
    fn head(&self, t: usize) -> usize {
        if t < self.nt {
            self.link(t)
        } else {
            NIL
        }
    }

    #[inline]
    fn set_head(&mut self, t: usize, c: usize) {
        if t < self.nt {
            self.set_link(t, c);
        }
    }

    #[inline]
    fn next(&self, c: usize) -> usize {
        self.link(self.nt.saturating_add(c))
    }

    #[inline]
    fn set_next(&mut self, c: usize, n: usize) {
        self.set_link(self.nt.saturating_add(c), n);
    }

    /// Puts control point `c` at the front of triangle `t`'s list.
    fn push(&mut self, t: usize, c: usize) {
        let h = self.head(t);
        self.set_next(c, h);
        self.set_head(t, c);
    }

    /// Control point `c`'s position in the mesh's normalised units.
    fn point<L: Index>(&self, mesh: &Mesh<'_, L, I>, c: usize) -> V3 {
        if c < self.nt {
            let t = self.original.get(c).copied().unwrap_or([I::ZERO; 3]);
            let p = t.map(|v| mesh.p(v.to_usize()));
            math::scale(math::add(math::add(p[0], p[1]), p[2]), 1.0 / 3.0)
        } else {
            mesh.p(c - self.nt)
        }
    }

    /// A guard for list walks: more steps than control points means a broken list.
    fn guard(&self) -> usize {
        self.links.len()
    }

    /// Enrols every control point on the freshly built mesh (before any collapse): each live
    /// triangle's centroid on itself, each feature-edge vertex on its first triangle.
    pub(crate) fn enrol<L: Index>(&mut self, mesh: &Mesh<'_, L, I>, max_error: f32) {
        for k in self.links.iter_mut() {
            *k = K::NIL;
        }
        let d = mesh.normalised_length(max_error);
        let d2 = d * d;
        self.limit2 = if d2.is_nan() { 0.0 } else { d2 };
        for t in 0..self.nt {
            if !crate::mesh::is_dead(mesh.tri(t)) {
                self.push(t, t);
            }
        }
        for v in 0..mesh.vertex_count() {
            let f = mesh.first(v);
            if f != NIL && self.on_feature_edge(mesh, v) {
                self.push(f >> 2, self.nt.saturating_add(v));
            }
        }
    }

    /// Whether one of `v`'s edges is a feature edge: a boundary or non-manifold edge, or one
    /// whose two triangles' normals differ by more than the feature angle.
    fn on_feature_edge<L: Index>(&self, mesh: &Mesh<'_, L, I>, v: usize) -> bool {
        for (t, k) in mesh.corners(v) {
            let tri = mesh.tri(t);
            for x in [tri[next3(k)], tri[prev3(k)]] {
                let mut other = NIL;
                let mut count = 0;
                for (u, _) in mesh.corners(v) {
                    if u != t && mesh.tri(u).contains(&x) {
                        other = u;
                        count += 1;
                    }
                }
                if count != 1 {
                    return true;
                }
                let n1 = normal(mesh, tri);
                let n2 = normal(mesh, mesh.tri(other));
                let (l1, l2) = (math::dot(n1, n1), math::dot(n2, n2));
                if l1 > math::TINY2 && l2 > math::TINY2 && l1.is_finite() && l2.is_finite() {
                    let c = math::dot(n1, n2) * math::rsqrt(l1) * math::rsqrt(l2);
                    if c < self.cos_feature {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Calls `f` on each triangle of `b`'s fan after `a -> b` (without changing the mesh);
    /// stops as soon as `f` returns `true` and returns whether it did.
    fn new_fan<L: Index>(
        mesh: &Mesh<'_, L, I>,
        a: usize,
        b: usize,
        mut f: impl FnMut([V3; 3]) -> bool,
    ) -> bool {
        let pb = mesh.p(b);
        for (t, k) in mesh.corners(a) {
            let tri = mesh.tri(t);
            if tri.contains(&b) {
                continue;
            }
            let mut p = tri.map(|v| mesh.p(v));
            if let Some(x) = p.get_mut(k) {
                *x = pb;
            }
            if f(p) {
                return true;
            }
        }
        for (t, _) in mesh.corners(b) {
            let tri = mesh.tri(t);
            if tri.contains(&a) {
                continue;
            }
            if f(tri.map(|v| mesh.p(v))) {
                return true;
            }
        }
        false
    }

    /// The veto (Zhu, Wang and Meng 2007 §3, steps 6-8): whether every control point of `a`'s
    /// triangles lies within `d_hold` of some triangle of `b`'s fan after `a -> b`.
    pub(crate) fn allows<L: Index>(&self, mesh: &Mesh<'_, L, I>, a: usize, b: usize) -> bool {
        if self.limit2 == f32::INFINITY {
            return true;
        }
        let mut guard = self.guard();
        for (t, _) in mesh.corners(a) {
            let mut c = self.head(t);
            while c != NIL {
                if guard == 0 {
                    return false;
                }
                guard -= 1;
                let p = self.point(mesh, c);
                let near = Self::new_fan(mesh, a, b, |q| {
                    point_triangle_distance2(p, q) <= self.limit2
                });
                if !near {
                    return false;
                }
                c = self.next(c);
            }
        }
        true
    }

    /// Before the collapse `a -> b`: takes the control points off `a`'s triangles and returns
    /// them as one chain (its first point, `NIL` if none).
    pub(crate) fn detach<L: Index>(&mut self, mesh: &Mesh<'_, L, I>, a: usize) -> usize {
        let mut chain = NIL;
        let mut guard = self.guard();
        for (t, _) in mesh.corners(a) {
            let mut c = self.head(t);
            self.set_head(t, NIL);
            while c != NIL && guard > 0 {
                guard -= 1;
                let n = self.next(c);
                self.set_next(c, chain);
                chain = c;
                c = n;
            }
        }
        chain
    }

    /// After the collapse onto `b`: gives each point of `chain` to its nearest triangle of `b`'s
    /// fan (ties: the lower slot; Zhu, Wang and Meng 2007 §3, the redistribution after a collapse).
    pub(crate) fn attach<L: Index>(&mut self, mesh: &Mesh<'_, L, I>, b: usize, chain: usize) {
        let mut c = chain;
        let mut guard = self.guard();
        while c != NIL && guard > 0 {
            guard -= 1;
            let n = self.next(c);
            let p = self.point(mesh, c);
            let mut best = (f32::INFINITY, NIL);
            for (t, _) in mesh.corners(b) {
                let d = point_triangle_distance2(p, mesh.tri(t).map(|v| mesh.p(v)));
                if best.1 == NIL || d < best.0 || (d == best.0 && t < best.1) {
                    best = (d, t);
                }
            }
            if best.1 != NIL {
                self.push(best.1, c);
            }
            c = n;
        }
    }

    /// `d_i,max` of Zhu, Wang and Meng 2007 eq. 3: the largest distance of triangle `t`'s control
    /// points to it, in normalised units (0 if it has none).
    pub(crate) fn max_distance<L: Index>(&self, mesh: &Mesh<'_, L, I>, t: usize) -> f32 {
        let q = mesh.tri(t).map(|v| mesh.p(v));
        let mut max = 0.0f32;
        let mut c = self.head(t);
        let mut guard = self.guard();
        while c != NIL && guard > 0 {
            guard -= 1;
            let d2 = point_triangle_distance2(self.point(mesh, c), q);
            if d2 > max {
                max = d2;
            }
            c = self.next(c);
        }
        sqrt(max)
    }

    /// `(E_max, E_mean)` in the input's units (Zhu, Wang and Meng 2007 §4, eq. 4-5): the largest
    /// distance of any control point (both kinds) to its controlled triangle, and the mean distance
    /// of the centroids weighted by their original triangles' areas.
    pub(crate) fn errors<L: Index>(&self, mesh: &Mesh<'_, L, I>) -> (f32, f32) {
        let (mut max, mut sum, mut area) = (0.0f32, 0.0f32, 0.0f32);
        let mut guard = self.guard();
        for t in 0..self.nt {
            let tri = mesh.tri(t);
            if crate::mesh::is_dead(tri) {
                continue;
            }
            let q = tri.map(|v| mesh.p(v));
            let mut c = self.head(t);
            while c != NIL && guard > 0 {
                guard -= 1;
                let d2 = point_triangle_distance2(self.point(mesh, c), q);
                let d = sqrt(d2);
                if d > max {
                    max = d;
                }
                if c < self.nt {
                    let o = self.original.get(c).copied().unwrap_or([I::ZERO; 3]);
                    let n = normal(mesh, o.map(|v| v.to_usize()));
                    let l2 = math::dot(n, n);
                    if l2 > math::TINY2 && l2.is_finite() {
                        let a = sqrt(l2);
                        sum += d * a;
                        area += a;
                    }
                }
                c = self.next(c);
            }
        }
        let mean = if area > 0.0 { sum / area } else { 0.0 };
        (mesh.input_length(max), mesh.input_length(mean))
    }
}

/// The (unnormalised) normal of triangle `tri`: twice its area in length.
fn normal<L: Index, I: Index>(mesh: &Mesh<'_, L, I>, tri: [usize; 3]) -> V3 {
    let [a, b, c] = tri.map(|v| mesh.p(v));
    math::cross(math::sub(b, a), math::sub(c, a))
}

#[cfg(test)]
mod tests {
    use super::point_triangle_distance2 as d2;

    #[test]
    fn point_triangle_regions() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(d2([0.25, 0.25, 2.0], t), 4.0);
        assert_eq!(d2([-1.0, -1.0, 0.0], t), 2.0);
        assert_eq!(d2([2.0, 0.0, 0.0], t), 1.0);
        assert_eq!(d2([0.0, 3.0, 0.0], t), 4.0);
        assert_eq!(d2([0.5, -1.0, 0.0], t), 1.0);
        assert_eq!(d2([-1.0, 0.5, 0.0], t), 1.0);
        assert!((d2([1.0, 1.0, 0.0], t) - 0.5).abs() < 1e-6);
        // Degenerate: a segment.
        let s = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert_eq!(d2([1.0, 1.0, 0.0], s), 1.0);
    }
}

//! Simplification envelopes: a two-sided bound on every surface point (Cohen, Varshney,
//! Manocha et al. 1996, as the survey seed 002 describes them: "采用等距面来限定简化模型顶点的变化范围").
//!
//! The original surface is offset along its vertex normals by `+ε_i` and `-ε_i`, giving the
//! outer and inner envelopes P(+ε) and P(-ε); `ε_i` starts at the bound `ε`
//! ([`Config::max_error`](crate::Config::max_error)) and is halved, round after round, at the
//! vertices of envelope triangles that meet a triangle of the surface or of the envelopes they
//! are not adjacent to, or that turned over (the seed's step: offsets may not intersect
//! themselves). A collapse or a vertex removal is then accepted only when every new triangle
//! lies strictly between the envelopes: it meets none of their triangles, by exact tests on a
//! fixed-point grid ([`crate::exact`]), found through a uniform grid of the original triangles
//! in the caller's memory.
//!
//! What that guarantees, for a closed manifold input whose envelopes do not intersect:
//! - every point of the result is within `ε` of the original (a new triangle inside the
//!   envelope lies in the union of the prisms between the offsets, each the convex hull of
//!   points within `ε_i ≤ ε` of an original triangle);
//! - every original point is within `ε` of the result: the segment from its point on P(-ε) to
//!   its point on P(+ε) (length `2ε_i` at most, through the point) crosses the surface an odd
//!   number of times before, and each operation replaces a disc by a disc with the same rim
//!   inside the envelope, which keeps that parity.
//!
//! Where the assumptions fail, the bound refuses rather than guesses:
//! - a **border** is kept: its vertices never go (the envelope would not stop a border from
//!   retreating; Cohen's border tubes are not built). The envelope is closed there by walls
//!   between the offsets of each border edge, moved outward by `0.3 ε_i` so that the kept
//!   vertex is strictly inside; such a vertex's normal offset is `0.7 ε_i`, so every envelope
//!   point stays within `ε_i` of the surface.
//! - a vertex whose normal is undefined or faces away from one of its triangles, a
//!   non-manifold or irregular vertex, and the vertices of **self-intersecting** parts (their
//!   envelopes meet whatever `ε_i`) get `ε_i = 0` after the last round: the envelope pinches to
//!   the surface there, so they never go and no new triangle may touch them.
//!
//! Storage, all the caller's: the original triangles (read only, they may stay in flash), a
//! shell of two vectors per position (the normal offset and the border push, 24 bytes), and
//! one slice of [`Index`] words ([`index_len`]): a border mask per triangle, the grid's cell
//! starts and its entries. Six words per triangle (12 bytes with `u16`) let the grid be as
//! fine as one cell per triangle; with fewer it is coarser and each test slower.

use crate::exact::{self, P};
use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::{flag, is_dead, next3, Mesh, NIL};

/// Halving rounds before the vertices still involved get `ε_i = 0`: `ε / 256` is below any
/// gap a mesh's own triangles leave, so what clashes then is the input meeting itself.
const ROUNDS: usize = 8;
/// The normal offset and the outward push of a border vertex, in units of `ε_i`: their sum is
/// 1, so an envelope point is never more than `ε_i` from its vertex.
const BORDER_OFFSET: f32 = 0.7;
const BORDER_PUSH: f32 = 0.3;
/// Largest cells per axis.
const MAX_SIDE: usize = 1024;
/// Bit of the mask word: the triangle has an envelope (it was live and not degenerate).
const UNIT: usize = 8;
/// Bit of the mask word while the envelope is built: a corner's offsets changed in the last
/// round, so the unit is tested again (a pair of unchanged units cannot start to clash, and a
/// changed unit is tested against all).
const CLASH: usize = 16;

/// Words of the index slice for `triangles` triangles: a mask per triangle, one cell per
/// triangle and four entries per triangle (a coarser grid is chosen if fewer are given).
pub const fn index_len(triangles: usize) -> usize {
    triangles.saturating_mul(6).saturating_add(2)
}

/// The uniform grid of the envelope triangles.
#[derive(Clone, Copy, Debug, Default)]
struct Grid {
    lo: V3,
    inv: f32,
    dims: [usize; 3],
    /// Where cell starts begin in the index slice, and where entries begin.
    starts: usize,
    entries: usize,
}

impl Grid {
    fn cells(&self) -> usize {
        self.dims[0]
            .saturating_mul(self.dims[1])
            .saturating_mul(self.dims[2])
    }

    /// The cell coordinates of `p` (clamped; NaN to 0).
    fn cell(&self, p: V3) -> [usize; 3] {
        let mut c = [0; 3];
        for ((c, (&x, &lo)), &d) in c.iter_mut().zip(p.iter().zip(&self.lo)).zip(&self.dims) {
            // `as` saturates: negative and NaN to 0.
            *c = (((x - lo) * self.inv) as usize).min(d.saturating_sub(1));
        }
        c
    }

    fn id(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// Calls `f` on each cell from `l` to `h` (corners included); stops when `f` returns
    /// `true` and returns whether it did.
    fn each_cell(
        &self,
        l: [usize; 3],
        h: [usize; 3],
        mut f: impl FnMut([usize; 3]) -> bool,
    ) -> bool {
        for z in l[2]..=h[2] {
            for y in l[1]..=h[1] {
                for x in l[0]..=h[0] {
                    if f([x, y, z]) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// A unit's points: for each corner of its original triangle, the position and the outer and
/// inner envelope points (normalised units). Read once per visit, for its box and triangles.
type Unit = [[V3; 3]; 3];

/// The box of a unit's envelope and surface.
fn unit_box(u: &Unit) -> Box3 {
    let [a, b, c] = *u;
    bbox(&[a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]])
}

/// An axis-aligned box.
type Box3 = (V3, V3);

fn bbox(points: &[V3]) -> Box3 {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        grow(&mut lo, &mut hi, (p, p));
    }
    (lo, hi)
}

/// Widens `(lo, hi)` to hold the box `(l, h)`.
fn grow(lo: &mut V3, hi: &mut V3, (l, h): (&V3, &V3)) {
    for ((lo, hi), (&l, &h)) in lo.iter_mut().zip(hi.iter_mut()).zip(l.iter().zip(h)) {
        *lo = lo.min(l);
        *hi = hi.max(h);
    }
}

fn overlap(a: &Box3, b: &Box3) -> bool {
    let le = |x: &V3, y: &V3| x.iter().zip(y).all(|(p, q)| p <= q);
    le(&a.0, &b.1) && le(&b.0, &a.1)
}

/// The envelope bound (see the module documentation), given to
/// [`Storage::start`](crate::Storage::start) as its bound with the bound's `ε` in
/// [`Config::max_error`](crate::Config::max_error) (finite, else
/// [`Error::InvalidConfig`](crate::Error::InvalidConfig) for `MaxError`).
///
/// Checked when the run starts: `original` must equal the triangles to simplify
/// ([`Error::OriginalMismatch`](crate::Error::OriginalMismatch)); `shell` must hold a pair per
/// position and `index` at least `2·T + 2` words numbered below `K`'s `NIL`, else
/// [`Error::Capacity`](crate::Error::Capacity) for [`Capacity::Envelope`](crate::Capacity::Envelope).
/// Runs with [`EdgeCollapse`](crate::EdgeCollapse) (subset placement) and with
/// [`VertexDecimation`](crate::VertexDecimation).
pub struct Envelope<'a, I: Index, K: Index> {
    original: &'a [[I; 3]],
    shell: &'a mut [[V3; 2]],
    index: &'a mut [K],
    nt: usize,
    grid: Grid,
}

impl<'a, I: Index, K: Index> Envelope<'a, I, K> {
    /// An envelope of the `original` triangles in `shell` and `index` (contents on entry do
    /// not matter); all three are checked when the run starts.
    pub fn new(original: &'a [[I; 3]], shell: &'a mut [[[f32; 3]; 2]], index: &'a mut [K]) -> Self {
        Envelope {
            original,
            nt: original.len(),
            shell,
            index,
            grid: Grid::default(),
        }
    }

    /// Checks the storage against the run (see [`Envelope`]).
    pub(crate) fn prepare(
        &mut self,
        triangles: &[[I; 3]],
        vertices: usize,
        config: &crate::Config,
    ) -> Result<(), crate::Error> {
        use crate::{Capacity, ConfigField, Error};
        if let Some(triangle) = crate::tri::first_difference(self.original, triangles) {
            return Err(Error::OriginalMismatch { triangle });
        }
        if !config.max_error.is_finite() {
            return Err(Error::InvalidConfig {
                field: ConfigField::MaxError,
            });
        }
        if self.shell.len() < vertices {
            return Err(Error::Capacity {
                what: Capacity::Envelope,
                needed: vertices,
                available: self.shell.len(),
            });
        }
        let need = triangles.len().saturating_mul(2).saturating_add(2);
        let available = self.index.len().min(K::COUNT);
        if need > available {
            return Err(Error::Capacity {
                what: Capacity::Envelope,
                needed: need,
                available,
            });
        }
        let index = core::mem::take(&mut self.index);
        self.index = index.get_mut(..available).unwrap_or(&mut []);
        Ok(())
    }

    #[inline]
    fn word(&self, i: usize) -> usize {
        match self.index.get(i) {
            Some(&k) if k != K::NIL => k.to_usize(),
            _ => 0,
        }
    }

    #[inline]
    fn set_word(&mut self, i: usize, v: usize) {
        if let Some(k) = self.index.get_mut(i) {
            *k = K::narrow(v);
        }
    }

    fn mask(&self, t: usize) -> usize {
        if t < self.nt {
            self.word(t)
        } else {
            0
        }
    }

    fn offsets(&self, v: usize) -> [V3; 2] {
        self.shell.get(v).copied().unwrap_or([[0.0; 3]; 2])
    }

    /// Whether `v` may go: inside the envelope with room on both sides, not on a border.
    fn removable<L: Index>(&self, mesh: &Mesh<'_, L, I>, v: usize) -> bool {
        let [u, l] = self.offsets(v);
        u != [0.0; 3] && l != [0.0; 3] && !mesh.has(v, flag::BOUNDARY)
    }

    /// The original vertices of triangle `t`.
    fn corners_of(&self, t: usize) -> [usize; 3] {
        self.original
            .get(t)
            .map_or([NIL; 3], |x| x.map(|v| v.to_usize()))
    }

    /// Triangle `t`'s unit: each corner's position, outer and inner point.
    fn unit<L: Index>(&self, mesh: &Mesh<'_, L, I>, t: usize) -> Unit {
        self.corners_of(t).map(|v| {
            let p = mesh.p(v);
            let [u, d] = self.offsets(v).map(|o| math::add(p, o));
            [p, u, d]
        })
    }

    /// The box of triangle `t`'s envelope and surface.
    fn box_of<L: Index>(&self, mesh: &Mesh<'_, L, I>, t: usize) -> Box3 {
        unit_box(&self.unit(mesh, t))
    }

    /// Unit `t`'s envelope triangles on the grid (its points `u`): the outer and the inner
    /// offset, then two walls per border edge; returns how many (at most 8: `out` keeps a
    /// place for the surface).
    fn unit_triangles(&self, t: usize, u: &Unit, out: &mut [[P; 3]; 9]) -> usize {
        let s = u.map(|[_, up, down]| [exact::snap(up), exact::snap(down)]);
        let [a, b, c] = s;
        out[0] = [a[0], b[0], c[0]];
        out[1] = [a[1], b[1], c[1]];
        let mut n = 2;
        let m = self.mask(t);
        for k in 0..3 {
            if m & (1 << k) != 0 {
                let (Some(&x), Some(&y)) = (s.get(k), s.get(next3(k))) else {
                    continue;
                };
                if let Some(w) = out.get_mut(n..n + 2) {
                    w[0] = [x[0], x[1], y[1]];
                    w[1] = [x[0], y[1], y[0]];
                    n += 2;
                }
            }
        }
        n
    }

    /// Calls `f` once for each envelope unit whose box meets `b`, with its points (each unit
    /// once: in the cell holding the low corner of the two boxes' overlap); stops when `f`
    /// returns `true` and returns whether it did.
    fn each_near<L: Index>(
        &self,
        mesh: &Mesh<'_, L, I>,
        b: &Box3,
        mut f: impl FnMut(usize, &Unit) -> bool,
    ) -> bool {
        let g = self.grid;
        if g.cells() == 0 {
            // No grid (no unit had a box): every unit, so that a missing index can only cost
            // time, never let a triangle through.
            return (0..self.nt).any(|t| {
                let u = self.unit(mesh, t);
                self.mask(t) & UNIT != 0 && overlap(b, &unit_box(&u)) && f(t, &u)
            });
        }
        g.each_cell(g.cell(b.0), g.cell(b.1), |c| {
            let id = g.id(c);
            let (s, e) = (self.word(g.starts + id), self.word(g.starts + id + 1));
            (s..e).any(|i| {
                let t = self.word(g.entries + i);
                let u = self.unit(mesh, t);
                let ub = unit_box(&u);
                if !overlap(b, &ub) {
                    return false;
                }
                let low = [
                    b.0[0].max(ub.0[0]),
                    b.0[1].max(ub.0[1]),
                    b.0[2].max(ub.0[2]),
                ];
                g.cell(low) == c && f(t, &u)
            })
        })
    }

    /// Whether the triangle `q` (on the grid, box `b`) meets the envelope (with `surface`,
    /// the original triangle too) of a unit `skip` lets through.
    fn meets<L: Index>(
        &self,
        mesh: &Mesh<'_, L, I>,
        q: [P; 3],
        b: &Box3,
        surface: bool,
        mut skip: impl FnMut(usize) -> bool,
    ) -> bool {
        self.each_near(mesh, b, |t, u| {
            if skip(t) {
                return false;
            }
            let mut e = [[[0; 3]; 3]; 9];
            let mut n = self.unit_triangles(t, u, &mut e);
            if surface {
                if let Some(x) = e.get_mut(n) {
                    *x = u.map(|[p, ..]| exact::snap(p));
                    n += 1;
                }
            }
            e.iter()
                .take(n)
                .any(|s| exact::triangles_meet_beyond(*s, q))
        })
    }

    /// Whether the new triangle with corners `tri` lies strictly inside the envelope.
    fn inside<L: Index>(&self, mesh: &Mesh<'_, L, I>, tri: [usize; 3]) -> bool {
        let p = tri.map(|v| mesh.p(v));
        let b = bbox(&p);
        !self.meets(mesh, p.map(exact::snap), &b, false, |_| false)
    }

    /// The veto for the half-edge collapse `a -> b`: `a` may go and each triangle of `b`'s new
    /// fan that is new (one of `a`'s, with `b` for `a`) is inside.
    pub(crate) fn allows<L: Index>(&self, mesh: &Mesh<'_, L, I>, a: usize, b: usize) -> bool {
        if !self.removable(mesh, a) {
            return false;
        }
        for (t, k) in mesh.corners(a) {
            let mut tri = mesh.tri(t);
            if tri.contains(&b) {
                continue;
            }
            if let Some(x) = tri.get_mut(k) {
                *x = b;
            }
            if !self.inside(mesh, tri) {
                return false;
            }
        }
        true
    }

    /// The veto for removing `v` and filling its hole with `new`.
    pub(crate) fn allows_fill<L: Index>(
        &self,
        mesh: &Mesh<'_, L, I>,
        v: usize,
        new: &[[usize; 3]],
    ) -> bool {
        self.removable(mesh, v) && new.iter().all(|&t| self.inside(mesh, t))
    }

    /// Builds the envelope on the freshly built mesh (before any operation): offsets, border
    /// walls, the grid, then the rounds that shrink offsets where envelopes meet.
    pub(crate) fn enrol<L: Index>(&mut self, mesh: &Mesh<'_, L, I>, max_error: f32) {
        // The snap's displacement and f32 rounding taken off, so that the bound holds in
        // input units.
        let eps = mesh.normalised_length(max_error) * 0.999 - 4.0 * exact::SNAP;
        let eps = if eps > 0.0 && eps.is_finite() {
            eps
        } else {
            0.0
        };
        let nv = mesh.vertex_count().min(self.shell.len());
        for s in self.shell.iter_mut() {
            *s = [[0.0; 3]; 2];
        }
        // Masks: units and border edges; area-weighted vertex normals into the shell.
        for t in 0..self.nt {
            let tri = mesh.tri(t);
            let mut m = 0;
            let n = normal(mesh, tri);
            if !is_dead(tri) && self.corners_of(t) == tri && n != [0.0; 3] {
                m = UNIT;
                for (k, (x, y)) in edges(tri).into_iter().enumerate() {
                    let mut count = 0;
                    for (u, _) in mesh.corners(x) {
                        count += mesh.tri(u).contains(&y) as usize;
                    }
                    if count == 1 {
                        m |= 1 << k;
                    }
                }
                for &v in &tri {
                    if let Some(s) = self.shell.get_mut(v) {
                        s[0] = math::add(s[0], n);
                    }
                }
            }
            self.set_word(t, m);
        }
        // Directions: unit normals; a vertex whose normal is undefined, faces away from one
        // of its triangles, or that is irregular gets none (pinched).
        for v in 0..nv {
            let [s, _] = self.offsets(v);
            let l2 = math::dot(s, s);
            let mut dir = if l2 > math::TINY2 && l2.is_finite() {
                math::unit_of(s, l2)
            } else {
                [0.0; 3]
            };
            if mesh.has(v, flag::LOCKED) {
                dir = [0.0; 3];
            }
            for (t, _) in mesh.corners(v) {
                if math::dot(normal(mesh, mesh.tri(t)), dir) <= 0.0 {
                    dir = [0.0; 3];
                }
            }
            if let Some(x) = self.shell.get_mut(v) {
                *x = [dir, [0.0; 3]];
            }
        }
        // Border pushes: the outward in-plane direction of each border edge, at both ends.
        for t in 0..self.nt {
            let m = self.mask(t);
            if m & UNIT == 0 {
                continue;
            }
            let tri = self.corners_of(t);
            let n = normal(mesh, tri);
            for (k, (x, y)) in edges(tri).into_iter().enumerate() {
                if m & (1 << k) == 0 {
                    continue;
                }
                let o = math::cross(math::sub(mesh.p(y), mesh.p(x)), n);
                let l2 = math::dot(o, o);
                if !(l2 > math::TINY2 && l2.is_finite()) {
                    continue;
                }
                let o = math::unit_of(o, l2);
                for v in [x, y] {
                    if let Some(s) = self.shell.get_mut(v) {
                        s[1] = math::add(s[1], o);
                    }
                }
            }
        }
        // The shell: each vertex's outer and inner point less its position.
        for v in 0..nv {
            let [d, w] = self.offsets(v);
            let on_border = mesh.has(v, flag::BOUNDARY) || w != [0.0; 3];
            let l2 = math::dot(w, w);
            let x = if !on_border {
                [math::scale(d, eps), math::scale(d, -eps)]
            } else if l2 > math::TINY2 && l2.is_finite() && d != [0.0; 3] {
                let push = math::scale(math::unit_of(w, l2), BORDER_PUSH * eps);
                [
                    math::add(math::scale(d, BORDER_OFFSET * eps), push),
                    math::add(math::scale(d, -BORDER_OFFSET * eps), push),
                ]
            } else {
                [[0.0; 3]; 2]
            };
            if let Some(s) = self.shell.get_mut(v) {
                *s = x;
            }
        }
        self.build_grid(mesh);
        self.shrink(mesh);
    }

    /// The finest grid (up to one cell per triangle) whose entries fit the index slice.
    fn build_grid<L: Index>(&mut self, mesh: &Mesh<'_, L, I>) {
        self.grid = Grid::default();
        let mut all: Box3 = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for t in 0..self.nt {
            if self.mask(t) & UNIT != 0 {
                let b = self.box_of(mesh, t);
                grow(&mut all.0, &mut all.1, (&b.0, &b.1));
            }
        }
        let ext = [
            all.1[0] - all.0[0],
            all.1[1] - all.0[1],
            all.1[2] - all.0[2],
        ];
        let side = math::max_abs(ext);
        if !(side > 0.0 && side.is_finite()) {
            return;
        }
        let room = self.index.len().saturating_sub(self.nt);
        // Cells: at most one per triangle and a fifth of the room (the rest for entries).
        let max_cells = self.nt.min(room / 5).max(1);
        let dims_for = |k: usize| {
            let h = side / k as f32;
            // Cells to cover the extent, rounded up (`cell` clamps the far side in): one
            // cell for `k = 1`, whose entries (one per unit) always fit.
            ext.map(|e| {
                let x = e / h;
                let c = x as usize;
                let c = if (c as f32) < x {
                    c.saturating_add(1)
                } else {
                    c
                };
                c.clamp(1, MAX_SIDE)
            })
        };
        let mut k = 1;
        while k < MAX_SIDE {
            let d = dims_for(k + 1);
            if d[0].saturating_mul(d[1]).saturating_mul(d[2]) > max_cells {
                break;
            }
            k += 1;
        }
        loop {
            let dims = dims_for(k);
            let mut g = Grid {
                lo: all.0,
                inv: k as f32 / side,
                dims,
                starts: self.nt,
                entries: 0,
            };
            let cells = g.cells();
            g.entries = g.starts + cells + 1;
            let mut count = 0usize;
            for t in 0..self.nt {
                if self.mask(t) & UNIT != 0 {
                    let (l, h) = self.span(mesh, &g, t);
                    count = count
                        .saturating_add((h[0] + 1 - l[0]) * (h[1] + 1 - l[1]) * (h[2] + 1 - l[2]));
                }
            }
            if g.entries.saturating_add(count) <= self.index.len() {
                self.fill_grid(mesh, g);
                return;
            }
            if k == 1 {
                return;
            }
            k = (k * 4 / 5).max(1);
        }
    }

    /// The cells unit `t`'s box covers, as a low and a high corner.
    fn span<L: Index>(
        &self,
        mesh: &Mesh<'_, L, I>,
        g: &Grid,
        t: usize,
    ) -> ([usize; 3], [usize; 3]) {
        let b = self.box_of(mesh, t);
        (g.cell(b.0), g.cell(b.1))
    }

    /// Counts, prefix sums and places every unit in the cells its box covers.
    fn fill_grid<L: Index>(&mut self, mesh: &Mesh<'_, L, I>, g: Grid) {
        let cells = g.cells();
        for c in 0..=cells {
            self.set_word(g.starts + c, 0);
        }
        // Counts, one word up: `starts + c + 1` counts cell `c`.
        for t in 0..self.nt {
            if self.mask(t) & UNIT == 0 {
                continue;
            }
            let (l, h) = self.span(mesh, &g, t);
            g.each_cell(l, h, |c| {
                let i = g.starts + g.id(c) + 1;
                let w = self.word(i);
                self.set_word(i, w + 1);
                false
            });
        }
        // Ends of each cell's run.
        let mut sum = 0;
        for c in 1..=cells {
            sum += self.word(g.starts + c);
            self.set_word(g.starts + c, sum);
        }
        // Placed from the back, so that each cell lists its units in ascending order and
        // `starts + c + 1` ends at the start of cell `c`.
        for t in (0..self.nt).rev() {
            if self.mask(t) & UNIT == 0 {
                continue;
            }
            let (l, h) = self.span(mesh, &g, t);
            g.each_cell(l, h, |c| {
                let i = g.starts + g.id(c) + 1;
                let pos = self.word(i).saturating_sub(1);
                self.set_word(i, pos);
                self.set_word(g.entries + pos, t);
                false
            });
        }
        // Shifted down one word, closed by the total.
        for c in 0..cells {
            let s = self.word(g.starts + c + 1);
            self.set_word(g.starts + c, s);
        }
        self.set_word(g.starts + cells, sum);
        self.grid = g;
    }

    /// The seed's reduction, for each envelope on its own: rounds that halve a vertex's
    /// outer (inner) offset when an outer (inner) triangle of its meets a triangle of the
    /// surface or of the envelopes of a unit it shares no vertex with, or turned over; a wall
    /// that meets one halves both. After the last round those offsets are 0 (pinched).
    fn shrink<L: Index>(&mut self, mesh: &Mesh<'_, L, I>) {
        const SIDES: [u8; 2] = [flag::MARK, flag::SEEN_B];
        for round in 0..=ROUNDS {
            let mut any = false;
            for t in 0..self.nt {
                let m = self.mask(t);
                if m & UNIT == 0 || (round > 0 && m & CLASH == 0) {
                    continue;
                }
                let hit = self.clashes(mesh, t);
                for (side, f) in SIDES.into_iter().enumerate() {
                    if hit & (1 << side) != 0 {
                        any = true;
                        for v in self.corners_of(t) {
                            mesh.set_flag(v, f, true);
                        }
                    }
                }
            }
            if !any || round == ROUNDS {
                for t in 0..self.nt {
                    let m = self.mask(t);
                    self.set_word(t, m & !CLASH);
                }
            }
            if !any {
                break;
            }
            for t in 0..self.nt {
                let m = self.mask(t);
                let changed = self
                    .corners_of(t)
                    .iter()
                    .any(|&v| SIDES.iter().any(|&f| mesh.has(v, f)));
                self.set_word(t, if changed { m | CLASH } else { m & !CLASH });
            }
            let f = if round == ROUNDS { 0.0 } else { 0.5 };
            for v in 0..mesh.vertex_count() {
                for (side, flag) in SIDES.into_iter().enumerate() {
                    if mesh.has(v, flag) {
                        mesh.set_flag(v, flag, false);
                        if let Some(x) = self.shell.get_mut(v).and_then(|s| s.get_mut(side)) {
                            *x = math::scale(*x, f);
                        }
                    }
                }
            }
        }
    }

    /// Which of unit `t`'s envelopes clash (bit 0 the outer, bit 1 the inner): an offset
    /// triangle turned over, or one of its triangles meets the surface or an envelope of a
    /// unit it shares no vertex with.
    fn clashes<L: Index>(&self, mesh: &Mesh<'_, L, I>, t: usize) -> u8 {
        let tri = self.corners_of(t);
        let u = self.unit(mesh, t);
        let mut e = [[[0; 3]; 3]; 9];
        let n = self.unit_triangles(t, &u, &mut e);
        let surface = u.map(|[p, ..]| exact::snap(p));
        let b = unit_box(&u);
        let adjacent = |u: usize| {
            let o = self.corners_of(u);
            u == t || o.iter().any(|v| tri.contains(v))
        };
        let mut hit = 0;
        for (i, &q) in e.iter().take(n).enumerate() {
            // Triangle 0 is the outer offset, 1 the inner, the rest walls (both).
            let side = match i {
                0 => 1,
                1 => 2,
                _ => 3,
            };
            if hit & side == side {
                continue;
            }
            let over = i < 2 && !exact::same_facing(q, surface);
            if over || self.meets(mesh, q, &b, true, adjacent) {
                hit |= side;
            }
        }
        hit
    }
}

/// A triangle's edges in winding order, edge `k` from corner `k` to the next.
fn edges([a, b, c]: [usize; 3]) -> [(usize, usize); 3] {
    [(a, b), (b, c), (c, a)]
}

/// The (unnormalised) normal of triangle `tri`: twice its area in length.
fn normal<L: Index, I: Index>(mesh: &Mesh<'_, L, I>, tri: [usize; 3]) -> V3 {
    let [a, b, c] = tri.map(|v| mesh.p(v));
    math::cross(math::sub(b, a), math::sub(c, a))
}

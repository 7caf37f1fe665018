//! integer: the pipeline's geometry in fixed point on a 15-bit grid, for cores without an
//! FPU (Cortex-M0/M0+, RV32IMC), where every `f32` operation is a library call. The same
//! decisions as `super::float`, each in integers whose widths are chosen so that nothing
//! overflows for any input on the grid; the bounds below are the reasons.
//!
//! **Positions.** `[u16; 3]` with every coordinate below 2¹⁵ ([`GRID`]): an edge `e` has
//! `|eᵢ| < 2¹⁵`, so a cross product of two edges, `|cᵢ| ≤ 2 (2¹⁵ - 1)² < 2³¹`, is exact in
//! `i32`. That is why the grid has 15 bits and not 16 (glTF's `KHR_mesh_quantization` and
//! meshoptimizer store up to 16): with 16, every normal would need 64-bit products, and a
//! Cortex-M0 has no 32×32→64 multiply. [`quantise`](super::quantise) puts a float mesh on the
//! grid.
//!
//! **Normals for the rules.** A normal is exact in `i32`; the flip and fold tests only compare
//! directions, so each normal is shifted (a per-vector exponent, [`norm14`]) until its largest
//! component is in `[2¹³, 2¹⁴)`: a dot product of two is below `3·2²⁸` (`i32`), a product of
//! two squared lengths below `2⁶⁰` (`u64`). The zero-area test uses the exact normal:
//! `|n|² ≤ 3·2⁶²` (`u64`), against `(s / 2¹³)²` with `s` the sum of squared edges
//! (`s < 2³⁴`): the float rule's `|n|² > 10⁻⁸ s²` with `2⁻²⁶` for `10⁻⁸`.
//!
//! **Quadrics.** A plane's unit normal in Q15 (from the shifted normal, its length by an
//! integer square root and one division) and its weight in [`AREA`] units (1/16 grid cell):
//! an area below `2^30.8` cells (`|c| < √3·2³¹`), times 16, times the border weight 10, is
//! below `2^38.2`; `n nᵀ` in Q22 (below `2²²`) times a weight fits `i64` (`< 2^60.2`), and a
//! fan's sum of at most 32 faces and its border and seam planes is below `2⁴⁴`. Summed in
//! `i64` ([`Sum`]), a quadric is then stored shifted so that its trace (the planes' weight
//! `W`) has 26 bits: five entries in `i32` (the sixth is the trace less the other two
//! diagonal ones) and the trace with its shift in one `u32` ([`Quadric`], 24 bytes, as a
//! float quadric).
//!
//! **Prices.** `raw = dᵀ S d` with `|dᵢ dⱼ| < 2³⁰` and entries below `2²⁶`: nine terms below
//! `2⁵⁶` each (`i64`). The error, `raw / W` (a mean squared distance), is kept in 1/256 grid
//! cells² ([`Err`] units) below `2⁴⁰`; a price is the error times `W + Ā` (meshoptimizer's
//! weight over the fan's area, as the float cost), up to `2⁸⁴`, so it is stored as a
//! [`pack`]ed `u32`: a 6-bit exponent and 26 bits of mantissa, ordered as the value (as an
//! `f32`'s bits are), and binned by its top 10 bits.

use super::geometry::{Geometry, Goal, Integer};
use super::{Arithmetic, BINS};
use crate::error::{Capacity, Error};
use crate::index::Index;
use crate::legality::Reject;

/// Coordinates are below this (15 bits).
pub const GRID: u16 = 1 << 15;

/// Quadric and area units per grid cell (an area of one cell² is 16).
const AREA: u32 = 16;
/// Error units per grid cell² (an error of one cell² is 256).
const ERR: u64 = 256;

/// meshoptimizer's `kEdgeWeightBorder`, as in the float pipeline.
const BORDER_WEIGHT: u64 = 10;
/// The seam planes' weight, the float pipeline's 0.1 (a division by 10).
const SEAM_DIVISOR: u64 = 10;
/// The fold limit `0.89²` in Q16 (rounded up: refuses a hair more than the float test).
const FOLD2_Q16: u64 = 51_911;
/// The sliver preference's `quality² = 12 |n|² / s²` floor, `0.05²`, as `12 |n|² · 4800 < s²`
/// (`1 / 0.05² = 400`, times 12).
const THIN: u64 = 4_800;

/// A grid position in the run.
pub(crate) type P = [i32; 3];

/// The integer frame: the grid positions and the unit the border planes' length weight is
/// measured in (so that a border's plane weighs against the faces as it does in the float
/// unit frame).
#[derive(Clone, Copy)]
pub struct Grid<'p> {
    positions: &'p [[u16; 3]],
    /// `AREA · E`, with `E` the power of two with the grid extent over `E` in `[1, 2)`: the
    /// float pipeline's edge weight `10 · length` in its unit frame is `10 · length · E` cells²
    /// here.
    edge_unit: u64,
}

/// A quadric being summed: the six entries of `Σ w n nᵀ` in [`AREA`] units.
pub(crate) type Sum = [i64; 6];

/// A stored quadric: `Σ w n nᵀ` shifted right by `k` so that its trace `W'` has at most 26
/// bits. `s` holds entries xx, xy, xz, yy, yz (zz is `W' - xx - yy`); `wk` is `W' << 6 | k`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quadric {
    s: [i32; 5],
    wk: u32,
}

impl Quadric {
    const ZERO: Quadric = Quadric { s: [0; 5], wk: 0 };

    /// `W'` and `k`.
    #[inline]
    fn weight(&self) -> (u64, u32) {
        (u64::from(self.wk >> 6), self.wk & 63)
    }
}

impl Arithmetic for Integer {
    type Position = [u16; 3];
    type Stored = Quadric;
    const EMPTY: Quadric = Quadric::ZERO;
    type Frame<'p> = Grid<'p>;

    #[inline(always)]
    fn frame<'p, I: Index>(
        positions: &'p [[u16; 3]],
        triangles: &[[I; 3]],
        capacity: (usize, usize),
        used: &mut [u8],
    ) -> Result<Grid<'p>, Error> {
        validate(positions, triangles, capacity, used)
    }
}

/// Checks capacities, indices and coordinates (below [`GRID`]), the first bad one in corner
/// order, and measures the grid extent. Writes only `used` (scratch).
#[inline(never)]
fn validate<'p, I: Index>(
    positions: &'p [[u16; 3]],
    triangles: &[[I; 3]],
    (vertices, capacity): (usize, usize),
    used: &mut [u8],
) -> Result<Grid<'p>, Error> {
    super::build::fits((positions.len(), triangles.len()), (vertices, capacity))?;
    let used = used.get_mut(..positions.len()).unwrap_or(&mut []);
    used.fill(0);
    let (mut lo, mut hi) = ([u16::MAX; 3], [0u16; 3]);
    for (t, tr) in triangles.iter().enumerate() {
        for &i in tr {
            let v = i.to_usize();
            let (Some(p), Some(u)) = (positions.get(v), used.get_mut(v)) else {
                return Err(Error::IndexOutOfRange {
                    triangle: t,
                    index: v,
                });
            };
            if *u != 0 {
                continue;
            }
            *u = 1;
            for ((&x, l), h) in p.iter().zip(lo.iter_mut()).zip(hi.iter_mut()) {
                if x >= GRID {
                    return Err(Error::OffGrid { vertex: v });
                }
                *l = (*l).min(x);
                *h = (*h).max(x);
            }
        }
    }
    let extent = hi[0]
        .saturating_sub(lo[0])
        .max(hi[1].saturating_sub(lo[1]))
        .max(hi[2].saturating_sub(lo[2]));
    // The power of two at or below the extent (1 for a point).
    let e = if extent == 0 {
        1
    } else {
        1u64 << (15 - extent.leading_zeros())
    };
    Ok(Grid {
        positions,
        edge_unit: u64::from(AREA) * e,
    })
}

/// Bits of `x` (0 for 0).
#[inline]
fn bits(x: u64) -> u32 {
    64 - x.leading_zeros()
}

/// `⌊√x⌋`, digit by digit (no division: a Cortex-M0 has none).
#[inline(never)]
fn isqrt(x: u64) -> u64 {
    let (mut x, mut r) = (x, 0u64);
    let mut b = 1u64 << ((bits(x).saturating_sub(1)) & !1);
    while b != 0 {
        if x >= r + b {
            x -= r + b;
            r = (r >> 1) + b;
        } else {
            r >>= 1;
        }
        b >>= 2;
    }
    r
}

#[inline]
fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The cross product of two edges (`|aᵢ|, |bᵢ| < 2¹⁵`): exact in `i32`.
#[inline]
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|v|²` of an `i32` vector, exact (`< 3·2⁶²`).
#[inline]
fn len2(v: P) -> u64 {
    v.iter()
        .map(|&x| (i64::from(x) * i64::from(x)) as u64)
        .sum()
}

/// `|e|²` of an edge (`< 3·2³⁰`).
#[inline]
fn edge2(e: P) -> u64 {
    len2(e)
}

/// `v` shifted (a per-vector exponent) so that its largest component is in `[2¹³, 2¹⁴)`, and
/// the shift (negative: shifted left, exactly); zero stays zero.
#[inline]
fn norm14(v: [i64; 3]) -> ([i32; 3], i32) {
    let m = v.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
    if m == 0 {
        return ([0; 3], 0);
    }
    let s = bits(m) as i32 - 14;
    let f = |x: i64| (if s >= 0 { x >> s } else { x << -s }) as i32;
    (v.map(f), s)
}

/// A normal shifted for the rules, and its squared length (`< 3·2²⁸`).
#[derive(Clone, Copy)]
pub struct Normal {
    n: [i32; 3],
    l2: u32,
}

#[inline]
fn shifted(c: P) -> Normal {
    let (n, _) = norm14(c.map(i64::from));
    let l2 = n.iter().map(|&x| (x * x) as u32).sum();
    Normal { n, l2 }
}

#[inline]
fn dot14(a: [i32; 3], b: [i32; 3]) -> i32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `⌊√x⌋` for `x` in `[2²⁶, 3·2²⁸]` (a shifted normal's squared length): two Newton steps
/// from a line through the ends of the range (within 13 %) and a last correction, so exactly
/// [`isqrt`]'s floor (over the whole range: checked exhaustively once, sampled by the unit
/// test) in fewer operations where a core divides in one instruction. Exact, not near: the
/// pipeline's order on flat CAD regions turns on the last bits of the planes.
#[inline]
fn root(x: u32) -> u32 {
    let y = (x >> 15) + 6_144;
    let y = (y + x / y) >> 1;
    let y = (y + x / y) >> 1;
    y - u32::from(y * y > x)
}

/// The unit vector of `v` in Q15 and `|v|` as `(ℓ, s)` with `|v| ≈ ℓ·2ˢ`, `ℓ < 2¹⁵`;
/// `None` for zero.
#[inline(never)]
fn unit(v: [i64; 3]) -> Option<([i32; 3], u64, i32)> {
    let (c, s) = norm14(v);
    unit_of(c, s)
}

/// [`unit`] of a cross product of two edges (an `i32` vector): 32-bit operations only.
#[inline(never)]
fn unit32(v: [i32; 3]) -> Option<([i32; 3], u64, i32)> {
    let m = v.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
    if m == 0 {
        return None;
    }
    let s = (32 - m.leading_zeros()) as i32 - 14;
    let c = v.map(|x| if s >= 0 { x >> s } else { x << -s });
    unit_of(c, s)
}

/// The unit vector of the shifted `c` (largest component in `[2¹³, 2¹⁴)`), with shift `s`.
#[inline(always)]
fn unit_of(c: [i32; 3], s: i32) -> Option<([i32; 3], u64, i32)> {
    // Below 3·2²⁸.
    let l2: u32 = c.iter().map(|&x| (x * x) as u32).sum();
    if l2 == 0 {
        return None;
    }
    // ℓ in [2¹³, 2^14.8): r = 2²⁹/ℓ below 2¹⁶, and |cᵢ| ≤ ℓ (to the root's precision) keeps
    // cᵢ·r near 2²⁹.
    let l = root(l2);
    let r = (1i32 << 29) / l as i32;
    Some((c.map(|x| (x * r) >> 14), u64::from(l), s))
}

/// `ℓ·2ˢ`, a length or area held as in [`unit`], times `m` (rounded down; saturating).
#[inline]
fn scaled(l: u64, s: i32, m: u64) -> u64 {
    let x = l.saturating_mul(m);
    if s >= 0 {
        x.checked_shl(s as u32).unwrap_or(u64::MAX)
    } else {
        x >> (-s) as u32
    }
}

/// Adds `w · n nᵀ` (`n` a unit vector in Q15, `w < 2^38.2`).
#[inline(never)]
fn add_plane(s: &mut Sum, n: [i32; 3], w: u64) {
    let w = w as i64;
    let [x, y, z] = n;
    // Q30 to Q22 (below 2²²), times w: below 2^60.2. Written out: no index to check.
    let nn = [x * x, x * y, x * z, y * y, y * z, z * z];
    for (e, p) in s.iter_mut().zip(nn) {
        *e += (i64::from(p >> 8) * w) >> 22;
    }
}

/// Packs a non-negative value into an ordered `u32`: below 2²⁵ as it is, above as a 6-bit
/// exponent and 25 bits of mantissa below the leading one (an `f32`'s layout), so that the
/// `u32`s order as the values; `x · 2^sh` for any `sh`.
#[inline]
pub(crate) fn pack(x: u64, sh: u32) -> u32 {
    let b = bits(x) + sh;
    if b <= 25 {
        return (x << sh) as u32;
    }
    let e = b - 25;
    if e >= 127 {
        return u32::MAX - 1;
    }
    // The 26 leading bits of x · 2^sh.
    let d = e - 1;
    let m = if sh >= d {
        x << (sh - d)
    } else {
        x >> (d - sh)
    };
    (e << 25) | (m as u32 & ((1 << 25) - 1))
}

/// The value of a packed `u32` as `(m, sh)`: `m · 2^sh`.
#[inline]
fn unpack(c: u32) -> (u64, u32) {
    let e = c >> 25;
    if e == 0 {
        (u64::from(c), 0)
    } else {
        (u64::from((c & ((1 << 25) - 1)) | (1 << 25)), e - 1)
    }
}

/// `a · b`, packed: each cut to 32 bits first, so the product fits `u64`.
#[inline]
fn pack_mul(a: u64, b: u64) -> u32 {
    let (sa, sb) = (bits(a).saturating_sub(32), bits(b).saturating_sub(32));
    pack((a >> sa) * (b >> sb), sa + sb)
}

/// The error of `raw` against trace `w` (`raw ≤ w · 3·2³⁰`): `raw / w` in [`ERR`] units, with
/// one 32-bit division (a 64-bit one is a library call on a 32-bit core): the numerator cut to
/// its 32 leading bits and the divisor to 16, a relative error below 2⁻¹⁴, finer than a
/// price's sort key.
#[inline]
fn mean(raw: u64, w: u64) -> u64 {
    if w == 0 || raw == 0 {
        return 0;
    }
    let sw = bits(w).saturating_sub(16);
    let d = (w >> sw) as u32;
    // raw = r · 2^t with r in [2³¹, 2³²).
    let t = bits(raw) as i32 - 32;
    let r = if t >= 0 { raw >> t } else { raw << -t } as u32;
    // d ≥ 1: w ≥ 1 keeps a bit after the shift.
    let q = u64::from(r / d.max(1));
    // raw · ERR / w = (r / d) · 2^(t + 8 - sw); t ≤ 27 and sw ≤ 10 keep the shifts below 64.
    let e = t + ERR.trailing_zeros() as i32 - sw as i32;
    if e >= 0 {
        q << e
    } else {
        q >> -e
    }
}

impl<'p> Grid<'p> {
    /// A frame on `positions` (for tests and the grid's users in the crate).
    #[cfg(test)]
    pub(crate) fn new(positions: &'p [[u16; 3]], extent_power: u64) -> Self {
        Grid {
            positions,
            edge_unit: u64::from(AREA) * extent_power,
        }
    }

    /// The plane through edge `e` (from the quadric's vertex) perpendicular to the triangle
    /// whose third vertex is at `o`, weighted by the edge's length times `num / den`.
    #[inline(never)]
    fn edge_plane(&self, s: &mut Sum, e: P, o: P, (num, den): (u64, u64)) {
        let l2 = edge2(e);
        let proj = i64::from(o[0]) * i64::from(e[0])
            + i64::from(o[1]) * i64::from(e[1])
            + i64::from(o[2]) * i64::from(e[2]);
        // |o|·|e|² and |e|·|proj| are below 2^47.6.
        let l2i = l2 as i64;
        let at = |o: i32, e: i32| i64::from(o) * l2i - i64::from(e) * proj;
        let perp = [at(o[0], e[0]), at(o[1], e[1]), at(o[2], e[2])];
        if l2 == 0 {
            return;
        }
        if let Some((n, _, _)) = unit(perp) {
            let w = isqrt(l2) * self.edge_unit * num / den.max(1);
            add_plane(s, n, w);
        }
    }

    /// The plane of triangle `p` weighted by its area times `m`.
    #[inline]
    fn plane(&self, s: &mut Sum, [p0, p1, p2]: [P; 3], m: u64) {
        let c = cross(sub(p1, p0), sub(p2, p0));
        if let Some((n, l, sh)) = unit32(c) {
            // Area = |c| / 2, in AREA units.
            add_plane(s, n, scaled(l, sh, u64::from(AREA) / 2 * m));
        }
    }
}

impl Geometry for Grid<'_> {
    type P = P;
    type Sum = Sum;
    type Q = Quadric;
    type Raw = u64;
    /// A packed price ([`pack`]).
    type Cost = u32;
    /// 1/256 grid cell².
    type Err = u64;
    /// 1/16 grid cell.
    type Area = u64;
    type N = Normal;

    const EMPTY: Sum = [0; 6];
    const RAW_MAX: u64 = u64::MAX;
    const COST_MAX: u32 = u32::MAX;
    const COST_ZERO: u32 = 0;
    const ERR_ZERO: u64 = 0;
    const ERR_MAX: u64 = u64::MAX;
    const AREA_ZERO: u64 = 0;
    const ORIGIN: P = [0; 3];

    #[inline]
    fn at(&self, v: usize) -> P {
        let p = self.positions.get(v).copied().unwrap_or([0; 3]);
        p.map(i32::from)
    }

    #[inline]
    fn face(&self, s: &mut Sum, p: [P; 3]) {
        self.plane(s, p, 1);
    }

    #[inline(never)]
    fn face_call(&self, s: &mut Sum, p: [P; 3]) {
        self.plane(s, p, 1);
    }

    #[inline(never)]
    fn border_edge(&self, s: &mut Sum, [p0, p1, p2]: [P; 3]) {
        let c = cross(sub(p1, p0), sub(p2, p0));
        if c == [0; 3] || p1 == p0 {
            return;
        }
        self.edge_plane(s, sub(p1, p0), sub(p2, p0), (BORDER_WEIGHT, 1));
        self.plane(s, [p0, p1, p2], BORDER_WEIGHT);
    }

    #[inline]
    fn seam_spoke(&self, s: &mut Sum, pv: P, pw: P, po: P) {
        self.edge_plane(s, sub(pw, pv), sub(po, pv), (1, SEAM_DIVISOR));
    }

    #[inline(never)]
    fn finish(&self, s: Sum) -> Quadric {
        let w = s[0] + s[3] + s[5];
        if w <= 0 {
            return Quadric::ZERO;
        }
        let k = bits(w as u64).saturating_sub(26);
        let sh = |x: i64| (x >> k).clamp(-(1 << 30), 1 << 30) as i32;
        let w = (w >> k) as u32;
        Quadric {
            s: [sh(s[0]), sh(s[1]), sh(s[2]), sh(s[3]), sh(s[4])],
            wk: (w << 6) | k,
        }
    }

    #[inline]
    fn face_area(&self, [p0, p1, p2]: [P; 3]) -> u64 {
        let c = cross(sub(p1, p0), sub(p2, p0));
        match unit32(c) {
            Some((_, l, sh)) => scaled(l, sh, u64::from(AREA) / 2),
            None => 0,
        }
    }

    #[inline(always)]
    fn add_area(a: u64, b: u64) -> u64 {
        a.saturating_add(b)
    }

    #[inline(always)]
    fn mean_area(total: u64, triangles: usize) -> u64 {
        total / (triangles.max(1) as u64)
    }

    #[inline]
    fn raw(&self, q: &Quadric, from: P, to: P) -> u64 {
        let d = sub(to, from).map(i64::from);
        let (w, _) = q.weight();
        let [xx, xy, xz, yy, yz] = q.s.map(i64::from);
        let zz = w as i64 - xx - yy;
        let e = xx * (d[0] * d[0])
            + yy * (d[1] * d[1])
            + zz * (d[2] * d[2])
            + 2 * (xy * (d[0] * d[1]) + xz * (d[0] * d[2]) + yz * (d[1] * d[2]));
        if e > 0 {
            e as u64
        } else {
            0
        }
    }

    #[inline]
    fn price(&self, mean_area: u64, q: &Quadric, raw: u64) -> u32 {
        let (w, k) = q.weight();
        // err · (W + Ā): the float price raw · (1 + Ā/W).
        let total = (w << k).saturating_add(mean_area);
        pack_mul(mean(raw, w), total)
    }

    #[inline]
    fn error(&self, _: u64, q: &Quadric, (from, to): (P, P), _: u32) -> u64 {
        mean(self.raw(q, from, to), q.weight().0)
    }

    #[inline(always)]
    fn cost_max(a: u32, b: u32) -> u32 {
        a.max(b)
    }

    #[inline]
    fn goal(cost: u32, goal: Goal) -> u32 {
        if cost >= u32::MAX - 1 {
            return cost;
        }
        let (m, sh) = unpack(cost);
        let m = match goal {
            Goal::Error => m * 9 / 10,
            Goal::Tail => m * 3 / 2,
        };
        pack(m, sh)
    }

    #[inline(always)]
    fn cost_bits(c: u32) -> u32 {
        c
    }

    #[inline(always)]
    fn cost_of(bits: u32) -> u32 {
        bits
    }

    /// The exponent (6 bits) and 4 bits of mantissa: a price below 2²⁵ (a flat collapse) in
    /// the first 16 bins.
    #[inline]
    fn key(bits: u32) -> usize {
        let k = (bits >> 21) as usize;
        if k < BINS {
            k
        } else {
            BINS - 1
        }
    }

    #[inline]
    fn limit(&self, distance: f32) -> u64 {
        // The one float operation of a run: the configuration's limit, in grid cells.
        if !distance.is_finite() {
            return u64::MAX;
        }
        // A finite limit stays finite (errors are measured under it), however large.
        ((distance * distance * ERR as f32) as u64).min(u64::MAX - 1)
    }

    #[inline(always)]
    fn over(e: u64, limit: u64) -> bool {
        e > limit
    }

    #[inline(always)]
    fn finite(e: u64) -> bool {
        e != u64::MAX
    }

    #[inline(always)]
    fn grow(e: u64, limit: u64) -> u64 {
        e.saturating_add(e / 2).min(limit)
    }

    #[inline]
    fn distance(&self, e: u64) -> f32 {
        // √(e / 256): in 1/16 cells.
        isqrt(e) as f32 / 16.0
    }

    #[inline]
    fn size(&self, a: P, b: P) -> u64 {
        edge2(sub(b, a)) * ERR
    }

    #[inline(always)]
    fn err_bits(e: u64) -> u32 {
        if e == u64::MAX {
            u32::MAX
        } else {
            pack(e, 0)
        }
    }

    #[inline(always)]
    fn err_of(bits: u32) -> u64 {
        if bits == u32::MAX {
            return u64::MAX;
        }
        let (m, sh) = unpack(bits);
        m.checked_shl(sh).unwrap_or(u64::MAX)
    }

    #[inline(always)]
    fn survivor(
        &self,
        [pa, pb, px, py]: [P; 4],
        (area, flip, thin): (bool, bool, bool),
    ) -> Result<Normal, Reject> {
        let c0 = cross(sub(px, pa), sub(py, pa));
        let c1 = cross(sub(px, pb), sub(py, pb));
        let abd = len2(c1);
        let s = edge2(sub(px, pb)) + edge2(sub(py, pb)) + edge2(sub(px, py));
        let t = s >> 13;
        if area && !(abd > 0 && abd > t * t) {
            return Err(Reject::Sliver);
        }
        let (n0, n1) = (shifted(c0), shifted(c1));
        let ndp = dot14(n0.n, n1.n);
        if flip
            && (ndp <= 0
                || (ndp as u64) * (ndp as u64) <= (u64::from(n0.l2) * u64::from(n1.l2)) >> 4)
        {
            return Err(Reject::NormalTurn);
        }
        if thin && thinner(abd, s, len2(c0), [px, py, pa]) {
            return Err(Reject::Sliver);
        }
        Ok(n1)
    }

    #[inline]
    fn normal(&self, [p0, p1, p2]: [P; 3]) -> Normal {
        shifted(cross(sub(p1, p0), sub(p2, p0)))
    }

    #[inline(always)]
    fn folded(a: Normal, b: Normal) -> bool {
        if b.l2 == 0 {
            return true;
        }
        let d = dot14(a.n, b.n);
        d < 0
            && (d as i64 * d as i64) as u64
                > ((u64::from(a.l2) * u64::from(b.l2)) >> 16) * FOLD2_Q16
    }

    #[inline(always)]
    fn fill_stored<I: Index, L: Index, const W: bool>(
        &self,
        triangles: &[[I; 3]],
        adj: (&[L], &[L]),
        flags: &mut [u8],
        border_next: &[L],
        stored: &mut [Quadric],
        all: bool,
    ) -> Option<u64> {
        // Each due vertex's quadric from its fan (summed wide, stored narrow: a scatter by
        // triangle would have to store the wide sums).
        for v in 0..flags.len() {
            if !super::fill::due(flags, v, all) {
                continue;
            }
            let q = super::fill::vertex_quadric::<I, L, _, super::fill::StoredBorders, W>(
                self,
                triangles,
                adj,
                (flags, border_next),
                &super::fill::StoredBorders,
                v,
            );
            if let Some(s) = stored.get_mut(v) {
                *s = q;
            }
        }
        for f in flags.iter_mut() {
            *f &= !super::flag::DIRTY;
        }
        None
    }
}

/// `l₀·l₁·l₂ < r₀·r₁·r₂` for `u64`s, each cut to 21 bits first (for the sliver preference's
/// fourth-degree products; a relative precision of 2⁻²⁰ is all a preference needs).
#[inline]
fn less(l: [u64; 3], r: [u64; 3]) -> bool {
    let product = |x: [u64; 3]| {
        let (mut p, mut e) = (1u64, 0u32);
        for v in x {
            let s = bits(v).saturating_sub(21);
            p *= v >> s;
            e += s;
        }
        (p, e)
    };
    let ((l, ls), (r, rs)) = (product(l), product(r));
    if l == 0 || r == 0 {
        return l == 0 && r != 0;
    }
    // Compare l · 2^ls with r · 2^rs: by bit length, then aligned (no overflow: equal lengths).
    let (bl, br) = (bits(l) + ls, bits(r) + rs);
    if bl != br {
        bl < br
    } else if ls >= rs {
        (l << (ls - rs)) < r
    } else {
        l < (r << (rs - ls))
    }
}

/// The float pipeline's sliver preference: `new < limit·s_new² && new·s_old² < old·s_new²`.
#[inline(never)]
fn thinner(new: u64, s_new: u64, old: u64, [px, py, pa]: [P; 3]) -> bool {
    let s_old = edge2(sub(px, pa)) + edge2(sub(py, pa)) + edge2(sub(px, py));
    less([new, THIN, 1], [s_new, s_new, 1]) && less([new, s_old, s_old], [old, s_new, s_new])
}

/// The grid a float mesh was put on by [`quantise`]: position `q` stands for
/// `origin + q · step`, with `step` a power of two and `origin` a multiple of it, so that the
/// sum is exact in `f32` (for a mesh within 2²⁴ cells of the origin) and quantising the grid's
/// positions again gives the same mesh, up to a shift by whole cells.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridFrame {
    /// The grid's corner, at or below the bounding box's.
    pub origin: [f32; 3],
    /// One grid cell.
    pub step: f32,
}

impl GridFrame {
    /// The float position of grid position `q`.
    pub fn position(&self, q: [u16; 3]) -> [f32; 3] {
        let ([x, y, z], [ox, oy, oz], s) = (q, self.origin, self.step);
        [
            ox + f32::from(x) * s,
            oy + f32::from(y) * s,
            oz + f32::from(z) * s,
        ]
    }

    /// The most a position moves by quantisation: half a cell's diagonal, `step · √3 / 2`.
    pub fn error(&self) -> f32 {
        self.step * 0.866_025_4
    }
}

/// The smallest power of two at or above a positive normal `x`, and below `2¹²⁷`.
fn pow2_at_least(x: f32) -> f32 {
    if x.is_nan() || x < f32::MIN_POSITIVE {
        return f32::MIN_POSITIVE;
    }
    let b = x.to_bits();
    let e = (b >> 23) + u32::from(b & 0x7f_ffff != 0);
    f32::from_bits(e.min(253) << 23)
}

/// `⌊x⌋` for a finite `x` (saturating at `i64`'s range).
fn floor(x: f32) -> f32 {
    let t = x as i64 as f32;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

/// Puts `positions` on a 15-bit grid over their bounding box into `out`, for the integer
/// pipeline: the step the smallest power of two that spans the largest extent in 32 766
/// steps, each coordinate rounded to the nearest cell. Returns the grid, whose
/// [`GridFrame::error`] bounds how far a position moved. Errors: a non-finite coordinate
/// ([`Error::NonFinitePosition`]), `out` shorter than `positions` ([`Error::Capacity`]).
pub fn quantise(positions: &[[f32; 3]], out: &mut [[u16; 3]]) -> Result<GridFrame, Error> {
    let Some(out) = out.get_mut(..positions.len()) else {
        return Err(Error::Capacity {
            what: Capacity::Vertices,
            needed: positions.len(),
            available: out.len(),
        });
    };
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for (v, p) in positions.iter().enumerate() {
        for ((&x, l), h) in p.iter().zip(lo.iter_mut()).zip(hi.iter_mut()) {
            if !x.is_finite() {
                return Err(Error::NonFinitePosition { vertex: v });
            }
            if x < *l {
                *l = x;
            }
            if x > *h {
                *h = x;
            }
        }
    }
    if positions.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    let mut extent = 0.0f32;
    for (l, h) in lo.iter().zip(hi.iter()) {
        if h - l > extent {
            extent = h - l;
        }
    }
    // One cell of slack: the origin snaps down by less than a cell.
    let step = pow2_at_least(extent / f32::from(GRID - 2));
    let origin = lo.map(|l| floor(l / step) * step);
    let top = f32::from(GRID - 1);
    for (p, q) in positions.iter().zip(out.iter_mut()) {
        for ((&x, &o), c) in p.iter().zip(origin.iter()).zip(q.iter_mut()) {
            // Round half up; `as` saturates, and the box keeps it in [0, top].
            let x = (x - o) / step + 0.5;
            let x = if x < top { x } else { top };
            *c = x as u16;
        }
    }
    Ok(GridFrame { origin, step })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_root_of_a_shifted_length_is_the_floor() {
        let mut x = 1u32 << 26;
        for y in [(1u32 << 26) + 1, 3 << 28, (1 << 28) - 1, 1 << 28] {
            assert_eq!(u64::from(root(y)), isqrt(u64::from(y)), "{y}");
        }
        while x <= 3 << 28 {
            assert_eq!(u64::from(root(x)), isqrt(u64::from(x)), "{x}");
            x += 9_973;
        }
    }

    #[test]
    fn the_mean_is_the_quotient_to_its_precision() {
        for (raw, w) in [
            (1u64, 1u64),
            (1000, 3),
            (1 << 40, 12_345),
            (3 << 56, (1 << 26) - 1),
            (7, 1 << 25),
            (0, 5),
            (5, 0),
        ] {
            let want = if w == 0 {
                0
            } else {
                (raw as u128 * ERR as u128 / w as u128) as u64
            };
            let got = mean(raw, w);
            assert!(
                got.abs_diff(want) <= want >> 14,
                "{raw}/{w}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn packing_orders_as_the_values() {
        let xs = [
            0u64,
            1,
            2,
            (1 << 25) - 1,
            1 << 25,
            (1 << 25) + 1,
            (1 << 26) - 1,
            1 << 26,
            123_456_789,
            1 << 40,
            (1 << 40) + (1 << 20),
            u64::MAX >> 1,
            u64::MAX,
        ];
        for w in xs.windows(2) {
            assert!(pack(w[0], 0) <= pack(w[1], 0), "{} {}", w[0], w[1]);
        }
        for &x in &xs[..9] {
            let (m, sh) = unpack(pack(x, 0));
            assert!(m << sh <= x && x - (m << sh) <= x >> 25, "{x}");
        }
        // Shifted values order with unshifted ones; the largest exponent stays below MAX.
        assert!(pack(3, 30) > pack(1 << 31, 0));
        assert!(pack(u64::MAX, 60) < u32::MAX);
        assert!(Grid::key(pack(u64::MAX, 20)) < BINS);
    }

    #[test]
    fn square_roots_are_exact_floors() {
        for x in (0u64..5000).chain([u64::MAX, 3 << 62, (1 << 32) - 1, 1 << 32]) {
            let r = isqrt(x);
            assert!(
                r * r <= x && (r + 1).checked_mul(r + 1).is_none_or(|s| s > x),
                "{x}"
            );
        }
    }

    /// The extremes: every width in the module docs at its bound.
    #[test]
    fn the_extremes_of_the_grid_do_not_overflow() {
        let m = i32::from(GRID - 1);
        let positions = [
            [0u16; 3],
            [GRID - 1, 0, 0],
            [0, GRID - 1, 0],
            [0, 0, GRID - 1],
        ];
        let g = Grid::new(&positions, 1 << 14);
        // The largest cross product and area.
        let c = cross([m, -m, 0], [m, m, -m]);
        assert!(c.iter().all(|x| x.unsigned_abs() < 1 << 31));
        let big = [[0, 0, 0], [m, 0, 0], [0, m, m]];
        let mut s = Grid::EMPTY;
        // 32 faces at ten times the largest area, and border planes: the bound of a fan.
        for _ in 0..32 {
            g.border_edge(&mut s, big);
            g.plane(&mut s, big, 10);
        }
        assert!(s.iter().all(|x| x.unsigned_abs() < 1 << 44), "{s:?}");
        let q = g.finish(s);
        // The longest move prices without overflow, and an error is at most the move.
        let raw = g.raw(&q, [0; 3], [m, m, m]);
        let err = mean(raw, q.weight().0);
        assert!(err <= 3 * (m as u64) * (m as u64) * ERR + ERR, "{err}");
        assert!(g.price(u64::MAX >> 20, &q, raw) < u32::MAX);
        // The rules on the largest triangles.
        let r = g.survivor(
            [[0; 3], [m, m, m], [m, 0, 0], [0, m, 0]],
            (true, true, true),
        );
        assert!(r.is_err() || r.is_ok());
        let n = g.normal(big);
        assert!(!Grid::folded(n, n));
        let flipped = g.normal([big[0], big[2], big[1]]);
        assert!(Grid::folded(n, flipped));
    }

    #[test]
    fn a_flat_fan_prices_a_move_in_its_plane_at_zero() {
        let positions = [
            [100u16, 100, 50],
            [200, 100, 50],
            [100, 200, 50],
            [0, 100, 50],
        ];
        let g = Grid::new(&positions, 128);
        let mut s = Grid::EMPTY;
        g.face(&mut s, [g.at(0), g.at(1), g.at(2)]);
        g.face(&mut s, [g.at(0), g.at(2), g.at(3)]);
        let q = g.finish(s);
        assert_eq!(g.raw(&q, g.at(0), g.at(1)), 0);
        assert!(g.raw(&q, g.at(0), [100, 100, 60]) > 0);
    }

    #[test]
    fn quantised_positions_are_within_the_grid_error() {
        let positions = [[-1.5f32, 2.0, 0.25], [3.0, -7.0, 1.0], [0.1, 0.2, 0.3]];
        let mut out = [[0u16; 3]; 3];
        let g = quantise(&positions, &mut out).unwrap();
        for (p, q) in positions.iter().zip(out) {
            assert!(q.iter().all(|&x| x < GRID));
            let back = g.position(q);
            let d: f32 = (0..3).map(|k| (back[k] - p[k]).powi(2)).sum::<f32>().sqrt();
            assert!(d <= g.error() * 1.001, "{d} > {}", g.error());
        }
        assert_eq!(
            quantise(&[[f32::NAN, 0.0, 0.0]], &mut out),
            Err(Error::NonFinitePosition { vertex: 0 })
        );
        assert!(quantise(&positions, &mut [[0u16; 3]; 2]).is_err());
        // The grid's positions quantise to the same grid, up to whole cells.
        let back = out.map(|q| g.position(q));
        let mut again = [[0u16; 3]; 3];
        let h = quantise(&back, &mut again).unwrap();
        assert_eq!(h.step, g.step);
        for (q, r) in out.iter().zip(again) {
            assert_eq!(h.position(r), g.position(*q));
        }
    }
}

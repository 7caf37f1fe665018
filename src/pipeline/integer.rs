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
//! integer square root and one reciprocal) and its weight in [`AREA`] units (1/16 grid cell):
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
//!
//! **Cores without a divide, a long multiply or a count of leading zeros** (the Cortex-M0,
//! `cfg(armv6m)` from `build.rs`): the same numbers from routines without them ([`wide`],
//! [`root_by_table`], [`reciprocal_by_newton`], [`leading_zeros`]), each checked against the
//! native operation by the unit tests; where the core has the instruction, the instruction.
//!
//! **The configuration** is read from its floats' bits ([`ratio_of`], `limit`): the run has
//! no float operation at all.

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
const BORDER_WEIGHT: u32 = 10;
/// The seam planes' weight, the float pipeline's 0.1 (a division by 10).
const SEAM_DIVISOR: u16 = 10;
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
    edge_unit: u32,
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
        1u64 << (31 - leading_zeros(u32::from(extent)))
    };
    Ok(Grid {
        positions,
        edge_unit: AREA * e as u32,
    })
}

/// Bits of `x` (0 for 0).
#[inline]
fn bits(x: u64) -> u32 {
    let high = (x >> 32) as u32;
    if high != 0 {
        64 - leading_zeros(high)
    } else {
        32 - leading_zeros(x as u32)
    }
}

/// `x.leading_zeros()`: the core's instruction, or on a core without one (a Cortex-M0, where
/// it is a library call; an RV32 core without Zbb, where the compiler spells it out at every
/// use) a binary search, one copy.
#[inline(always)]
fn leading_zeros(x: u32) -> u32 {
    #[cfg(any(armv6m, all(target_arch = "riscv32", not(target_feature = "zbb"))))]
    return zeros_by_halving(x);
    #[cfg(not(any(armv6m, all(target_arch = "riscv32", not(target_feature = "zbb")))))]
    return x.leading_zeros();
}

/// [`leading_zeros`] by halving the window: 16, 8, 4, 2 and 1 bits.
#[cfg(any(
    armv6m,
    all(target_arch = "riscv32", not(target_feature = "zbb")),
    test
))]
#[inline(never)]
fn zeros_by_halving(x: u32) -> u32 {
    if x == 0 {
        return 32;
    }
    let (mut x, mut n) = (x, 0);
    for w in [16, 8, 4, 2] {
        if x >> (32 - w) == 0 {
            n += w;
            x <<= w;
        }
    }
    n + (!x >> 31)
}

/// Defines `⌊√x⌋` for one unsigned type, two bits at a time from the highest power of four the
/// type holds (no division: a Cortex-M0 has none; `const`, for the tables).
macro_rules! digit_root {
    ($(#[$attr:meta])* $name:ident: $t:ty) => {
        $(#[$attr])*
        const fn $name(x: $t) -> $t {
            let (mut x, mut r, mut b) = (x, 0, 1 << (<$t>::BITS - 2));
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
    };
}

digit_root!(
    /// `⌊√x⌋` of a `u64` (an error, once per run).
    #[inline(never)]
    isqrt: u64
);

digit_root!(
    /// `⌊√x⌋` in 32 bits (an edge's length; the tables' roots, at compile time).
    #[inline]
    root_by_digits: u32
);

/// `⌊a / d⌋` for a divisor below `2¹⁶`, by 16-bit digits: four 32-bit divisions (a 64-bit one
/// is a library call of a kilobyte on a 32-bit core).
#[inline]
fn div_short(a: u64, d: u16) -> u64 {
    let d = u32::from(d.max(1));
    let (mut q, mut r) = (0u64, 0u32);
    for shift in [48, 32, 16, 0] {
        // r < d < 2¹⁶: the digit fits.
        let x = (r << 16) | ((a >> shift) as u32 & 0xffff);
        q = (q << 16) | u64::from(x / d);
        r = x % d;
    }
    q
}

/// `⌊a / d⌋` for any `u32` divisor, a bit at a time (once per pass: the mean triangle area).
#[inline(never)]
fn div_long(a: u64, d: u32) -> u64 {
    let d = u64::from(d.max(1));
    let (mut q, mut r) = (0u64, 0u64);
    for i in (0..64).rev() {
        // r < d < 2³² before the shift.
        r = (r << 1) | ((a >> i) & 1);
        if r >= d {
            r -= d;
            q |= 1 << i;
        }
    }
    q
}

/// `a · b` in 64 bits, written out: the core's long multiply, or on a Cortex-M0, which has none
/// (an `i64` product there is a 64 × 64 library call), [`by_halves`]. For the two loops a run
/// spends most in (a plane's sum, a price); elsewhere [`wide`].
#[inline(always)]
fn wide_inline(a: i32, b: i32) -> i64 {
    #[cfg(armv6m)]
    return by_halves(a, b);
    #[cfg(not(armv6m))]
    return i64::from(a) * i64::from(b);
}

/// [`wide_inline`], one called copy on a Cortex-M0 (flash), written out elsewhere.
#[cfg_attr(armv6m, inline(never))]
#[cfg_attr(not(armv6m), inline(always))]
fn wide(a: i32, b: i32) -> i64 {
    wide_inline(a, b)
}

/// [`wide`] for unsigned factors.
#[cfg_attr(armv6m, inline(never))]
#[cfg_attr(not(armv6m), inline(always))]
fn wide_u(a: u32, b: u32) -> u64 {
    #[cfg(armv6m)]
    return by_halves_u(a, b);
    #[cfg(not(armv6m))]
    return u64::from(a) * u64::from(b);
}

/// `a · b` from four products of 16-bit halves, `a = a₁·2¹⁶ + a₀` with `a₀` unsigned: every
/// partial product fits 32 bits (`|a₁ b₀| < 2³¹`, `a₁ b₁ ≤ 2³⁰`, `a₀ b₀ < 2³²` unsigned).
#[cfg(any(armv6m, test))]
#[inline(always)]
fn by_halves(a: i32, b: i32) -> i64 {
    let (a1, a0) = (a >> 16, a & 0xffff);
    let (b1, b0) = (b >> 16, b & 0xffff);
    let mid = i64::from(a1 * b0) + i64::from(a0 * b1);
    (i64::from(a1 * b1) << 32) + (mid << 16) + i64::from(a0 as u32 * b0 as u32)
}

/// [`by_halves`] for unsigned factors.
#[cfg(any(armv6m, test))]
#[inline(always)]
fn by_halves_u(a: u32, b: u32) -> u64 {
    let (a1, a0) = (a >> 16, a & 0xffff);
    let (b1, b0) = (b >> 16, b & 0xffff);
    let mid = u64::from(a1 * b0) + u64::from(a0 * b1);
    (u64::from(a1 * b1) << 32) + (mid << 16) + u64::from(a0 * b0)
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
    v.iter().map(|&x| wide(x, x) as u64).sum()
}

/// `|e|²` of an edge (`< 3·2³⁰`): each square below `2³⁰`, in 32 bits.
#[inline]
fn edge2(e: P) -> u64 {
    e.iter().map(|&x| u64::from((x * x) as u32)).sum()
}

/// `v` shifted (a per-vector exponent) so that its largest component is in `[2¹³, 2¹⁴)`, and
/// the shift (negative: shifted left, exactly); zero stays zero.
#[inline]
fn norm14(v: [i64; 3]) -> ([i32; 3], i32) {
    let m = v.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
    if m < 1 << 31 {
        return norm14_32(v.map(|x| x as i32));
    }
    // |vᵢ| < 2⁴⁷ (an edge plane's): a fixed shift by 16 into `i32`, then the rest (s ≥ 18),
    // the same floor as one shift by s, without a 64-bit shift by a variable.
    let s = bits(m) as i32 - 14;
    (v.map(|x| ((x >> 16) as i32) >> (s - 16)), s)
}

/// A normal shifted for the rules, and its squared length (`< 3·2²⁸`).
#[derive(Clone, Copy)]
pub struct Normal {
    n: [i32; 3],
    l2: u32,
}

#[inline]
fn shifted(c: P) -> Normal {
    let (n, _) = norm14_32(c);
    let l2 = n.iter().map(|&x| (x * x) as u32).sum();
    Normal { n, l2 }
}

#[inline]
fn dot14(a: [i32; 3], b: [i32; 3]) -> i32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `⌊√x⌋` for `x` in `[2²⁶, 3·2²⁸]` (a shifted normal's squared length), exactly
/// [`isqrt`]'s floor, not near: the pipeline's order on flat CAD regions turns on the last bits
/// of the planes. Where a core divides in one instruction, two Newton steps from a line through
/// the ends of the range (within 13 %) and a last correction (checked exhaustively once,
/// sampled by the unit test); on a Cortex-M0, which has no divide, [`root_by_table`].
#[inline]
fn root(x: u32) -> u32 {
    #[cfg(armv6m)]
    return root_by_table(x);
    #[cfg(not(armv6m))]
    {
        let y = (x >> 15) + 6_144;
        let y = (y + x / y) >> 1;
        let y = (y + x / y) >> 1;
        y - u32::from(y * y > x)
    }
}

/// `⌊√(i·2²⁵)⌋` for `i` in `0..=32`: [`root_by_table`]'s chords.
#[cfg(any(armv6m, test))]
const CHORDS: [u16; 33] = {
    let mut t = [0; 33];
    let mut i = 0;
    while i < 33 {
        t[i] = root_by_digits((i as u32) << 25) as u16;
        i += 1;
    }
    t
};

/// `2²⁶ / √((i + ½)·2²⁵)`, that is `√(2²⁸ / (2i + 1))`, for `i` in `8..32`:
/// [`root_by_table`]'s Newton step on chord `i` (in Q27).
#[cfg(any(armv6m, test))]
const SLOPES: [u16; 32] = {
    let mut t = [0; 32];
    let mut i = 8;
    while i < 32 {
        t[i] = root_by_digits((1 << 28) / (2 * i as u32 + 1)) as u16;
        i += 1;
    }
    t
};

/// [`root`] without a divide: `x` times 4 if below `2²⁸` (`⌊√(4x)⌋ / 2 = ⌊√x⌋`), so in
/// `[2²⁸, 2³⁰)`; the chord of `√` over its 1/32 of `[0, 2³⁰)` ([`CHORDS`]); one Newton step
/// `y += (x - y²) / 2y` with `1 / 2y` taken at the chord's middle ([`SLOPES`]); then corrected
/// to the floor. Over the whole range (checked exhaustively once, sampled by the unit test)
/// the step's residual is below `2^18.3` (so its product with a slope below `2¹²` fits `i32`)
/// and the correction one unit at most.
#[cfg(any(armv6m, test))]
#[inline]
fn root_by_table(x: u32) -> u32 {
    let quarter = x < 1 << 28;
    let x = if quarter { x << 2 } else { x };
    // Below 32 (x < 2³⁰); the mask says so to the compiler: no bounds check.
    let i = (x >> 25) as usize & 31;
    let (t0, t1) = (u32::from(CHORDS[i]), u32::from(CHORDS[i + 1]));
    let y = t0 + ((((x & ((1 << 25) - 1)) >> 13) * (t1 - t0)) >> 12);
    let e = x.wrapping_sub(y * y) as i32;
    let y = (y as i32 + ((e * i32::from(SLOPES[i])) >> 27)) as u32;
    let y = y - u32::from(y * y > x);
    let y = y + u32::from((y + 1) * (y + 1) <= x);
    if quarter {
        y >> 1
    } else {
        y
    }
}

/// `⌊2²⁹ / ℓ⌋` for `ℓ` in `[2¹³, 2¹⁵)` (a shifted normal's length): the core's divide, or on a
/// Cortex-M0 [`reciprocal_by_newton`].
#[inline]
fn reciprocal(l: u32) -> u32 {
    #[cfg(armv6m)]
    return reciprocal_by_newton(l);
    #[cfg(not(armv6m))]
    return (1 << 29) / l;
}

/// [`reciprocal`] with 32-bit multiplies: `ℓ` doubled into `x` in `[2¹⁴, 2¹⁵)` if below
/// `2¹⁴`, `2³⁰ / x` from the line `95 484 - 2x` (within 6.1 %, the minimax line of `1/t` on
/// `[1, 2)`), two Newton steps `y += y (2³⁰ - x y) / 2³⁰` (the residual cut by 2¹² so that the
/// product fits `i32`: `|y| < 2^16.1` and, from 6.1 % down, `|2³⁰ - x y| < 2^26.9`), then
/// raised to the floor (the steps, from below, end at most 2 under it); checked against the
/// division for every `ℓ` by the unit test.
#[cfg(any(armv6m, test))]
#[inline]
fn reciprocal_by_newton(l: u32) -> u32 {
    let (x, half) = if l < 1 << 14 {
        (l << 1, false)
    } else {
        (l, true)
    };
    let mut y = 95_484 - 2 * x as i32;
    for _ in 0..2 {
        let e = (1u32 << 30).wrapping_sub(x * y as u32) as i32;
        y += (y * (e >> 12)) >> 18;
    }
    let y = y as u32;
    let y = y + u32::from(x * (y + 1) <= 1 << 30);
    let y = y + u32::from(x * (y + 1) <= 1 << 30);
    // ⌊2³⁰ / 2ℓ⌋ = ⌊2²⁹ / ℓ⌋; for ℓ = x, ⌊⌊2³⁰ / x⌋ / 2⌋.
    if half {
        y >> 1
    } else {
        y
    }
}

/// The unit vector of `v` in Q15 and `|v|` as `(ℓ, s)` with `|v| ≈ ℓ·2ˢ`, `ℓ < 2¹⁵`;
/// `None` for zero.
#[inline]
fn unit(v: [i64; 3]) -> Option<([i32; 3], u64, i32)> {
    let (c, s) = norm14(v);
    unit_of(c, s)
}

/// [`norm14`] of a cross product of two edges (`|vᵢ| < 2³¹`), in 32 bits.
#[inline]
fn norm14_32(v: [i32; 3]) -> ([i32; 3], i32) {
    let m = v.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
    if m == 0 {
        return ([0; 3], 0);
    }
    let s = (32 - leading_zeros(m)) as i32 - 14;
    (v.map(|x| if s >= 0 { x >> s } else { x << -s }), s)
}

/// [`unit`] of a cross product of two edges (an `i32` vector): 32-bit operations only.
#[inline]
fn unit32(v: [i32; 3]) -> Option<([i32; 3], u64, i32)> {
    let (c, s) = norm14_32(v);
    unit_of(c, s)
}

/// The unit vector of the shifted `c` (largest component in `[2¹³, 2¹⁴)`), with shift `s`.
#[inline(never)]
fn unit_of(c: [i32; 3], s: i32) -> Option<([i32; 3], u64, i32)> {
    // Below 3·2²⁸.
    let l2: u32 = c.iter().map(|&x| (x * x) as u32).sum();
    if l2 == 0 {
        return None;
    }
    // ℓ in [2¹³, 2^14.8): r = 2²⁹/ℓ below 2¹⁶, and |cᵢ| ≤ ℓ (to the root's precision) keeps
    // cᵢ·r near 2²⁹.
    let l = root(l2);
    let r = reciprocal(l) as i32;
    Some((c.map(|x| (x * r) >> 14), u64::from(l), s))
}

/// `ℓ·2ˢ`, a length or area held as in [`unit`], times `m` (rounded down; saturating).
#[inline]
fn scaled(l: u64, s: i32, m: u32) -> u64 {
    // ℓ < 2¹⁵.
    let x = wide_u(l as u32, m);
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
    // A weight below 2³¹ (all but the largest triangles): 32 × 32 bits.
    let short = i32::try_from(w).ok();
    for (e, p) in s.iter_mut().zip(nn) {
        *e += match short {
            Some(w) => wide_inline(p >> 8, w),
            None => i64::from(p >> 8) * w,
        } >> 22;
    }
}

/// Packs a non-negative value into an ordered `u32`: below 2²⁵ as it is, above as a 6-bit
/// exponent and 25 bits of mantissa below the leading one (an `f32`'s layout), so that the
/// `u32`s order as the values; `x · 2^sh` for any `sh`.
#[inline(never)]
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
    pack(wide_u((a >> sa) as u32, (b >> sb) as u32), sa + sb)
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
            edge_unit: AREA * extent_power as u32,
        }
    }

    /// The plane through edge `e` (from the quadric's vertex) perpendicular to the triangle
    /// whose third vertex is at `o`, weighted by the edge's length times `num / den`.
    #[inline(never)]
    fn edge_plane(&self, s: &mut Sum, e: P, o: P, (num, den): (u32, u16)) {
        let l2 = edge2(e);
        if l2 == 0 {
            return;
        }
        // o |e|² - e (o·e), as e × (o × e): `o × e` is exact in `i32`, and each product of
        // the outer cross below 2⁴⁶.
        let c = cross(o, e);
        let perp = [
            wide(e[1], c[2]) - wide(e[2], c[1]),
            wide(e[2], c[0]) - wide(e[0], c[2]),
            wide(e[0], c[1]) - wide(e[1], c[0]),
        ];
        if let Some((n, _, _)) = unit(perp) {
            // ℓ < 2^15.8, and the unit times the border weight below 2²⁴.
            let w = wide_u(root_by_digits(l2 as u32), self.edge_unit * num);
            let w = if den > 1 { div_short(w, den) } else { w };
            add_plane(s, n, w);
        }
    }

    /// The plane of triangle `p` weighted by its area times `m`.
    #[inline]
    fn plane(&self, s: &mut Sum, [p0, p1, p2]: [P; 3], m: u32) {
        let c = cross(sub(p1, p0), sub(p2, p0));
        if let Some((n, l, sh)) = unit32(c) {
            // Area = |c| / 2, in AREA units.
            add_plane(s, n, scaled(l, sh, AREA / 2 * m));
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
            Some((_, l, sh)) => scaled(l, sh, AREA / 2),
            None => 0,
        }
    }

    #[inline(always)]
    fn add_area(a: u64, b: u64) -> u64 {
        a.saturating_add(b)
    }

    #[inline(always)]
    fn mean_area(total: u64, triangles: usize) -> u64 {
        div_long(total, u32::try_from(triangles).unwrap_or(u32::MAX))
    }

    #[inline]
    fn raw(&self, q: &Quadric, from: P, to: P) -> u64 {
        // |dᵢ dⱼ| < 2³⁰ and, the diagonal entries being non-negative parts of the trace,
        // |zz| ≤ W' < 2²⁶: every factor in 32 bits.
        let d = sub(to, from);
        let (w, _) = q.weight();
        let [xx, xy, xz, yy, yz] = q.s;
        let zz = (w as i32).wrapping_sub(xx).wrapping_sub(yy);
        let e = wide_inline(xx, d[0] * d[0])
            + wide_inline(yy, d[1] * d[1])
            + wide_inline(zz, d[2] * d[2])
            + 2 * (wide_inline(xy, d[0] * d[1])
                + wide_inline(xz, d[0] * d[2])
                + wide_inline(yz, d[1] * d[2]));
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
        // m < 2²⁶: the products fit 32 bits.
        let m = m as u32;
        let m = match goal {
            Goal::Error => m * 9 / 10,
            Goal::Tail => m * 3 / 2,
        };
        pack(u64::from(m), sh)
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

    fn target(target: crate::Target, valid: usize) -> usize {
        match target {
            crate::Target::Ratio(r) => ratio_of(r, valid),
            crate::Target::Triangles(n) => n,
        }
    }

    #[inline]
    fn limit(&self, distance: f32) -> u64 {
        // ⌊d² · ERR⌋ from d's bits (its sign squared away); an infinite or NaN limit is none.
        let Some((m, e)) = parts(f32::from_bits(distance.to_bits() & 0x7fff_ffff)) else {
            return u64::MAX;
        };
        // A finite limit stays finite (errors are measured under it), however large.
        shift_floor(wide_u(m, m), 2 * e + ERR.trailing_zeros() as i32).min(u64::MAX - 1)
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
        sixteenths(isqrt(e))
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
        if flip && (ndp <= 0 || wide_u(ndp as u32, ndp as u32) <= wide_u(n0.l2, n1.l2) >> 4) {
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
        d < 0 && wide(d, d) as u64 > (wide_u(a.l2, b.l2) >> 16) * FOLD2_Q16
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

/// A non-negative finite `x` as `(m, e)` with `x = m·2ᵉ`, `m < 2²⁴`, read from its bits (the
/// configuration's floats enter the run this way: a float operation is a library call on a
/// core without an FPU); `None` for a negative, infinite or NaN one.
#[inline]
fn parts(x: f32) -> Option<(u32, i32)> {
    let b = x.to_bits();
    let (exponent, fraction) = ((b >> 23) as i32, b & 0x7f_ffff);
    match exponent {
        0 => Some((fraction, -149)),
        1..=254 => Some((fraction | 0x80_0000, exponent - 150)),
        _ => None,
    }
}

/// `⌊x · 2ᵗ⌋`, saturating at `u64::MAX`.
#[inline]
fn shift_floor(x: u64, t: i32) -> u64 {
    if x == 0 || t <= -64 {
        0
    } else if t <= 0 {
        x >> -t
    } else if bits(x) as i32 + t > 64 {
        u64::MAX
    } else {
        x << t
    }
}

/// `x` rounded to 24 significant bits, ties to even (an `f32`'s rounding), as `(m, e)`:
/// `m·2ᵉ` with `m < 2²⁴`.
#[inline(never)]
fn round24(x: u64) -> (u64, i32) {
    let b = bits(x);
    if b <= 24 {
        return (x, 0);
    }
    let sh = b - 24;
    let (q, rest, half) = (x >> sh, x & ((1 << sh) - 1), 1u64 << (sh - 1));
    let q = q + u64::from(rest > half || (rest == half && q & 1 == 1));
    // Rounded up to 2²⁴: one bit fewer, exactly.
    if q >> 24 != 0 {
        (q >> 1, sh as i32 + 1)
    } else {
        (q, sh as i32)
    }
}

/// `(r * n as f32) as usize` (a target ratio's count) for a ratio in `[0, 1]` (validated), the
/// same number without a float operation: `n` and the product each rounded as an `f32` is, the
/// product floored (at most `n` rounded as an `f32`); 0 for a NaN or negative ratio.
fn ratio_of(r: f32, n: usize) -> usize {
    let Some((mr, er)) = parts(r) else {
        return 0;
    };
    let (mn, en) = round24(n as u64);
    // mr, mn < 2²⁴: exact in 48 bits.
    let (q, sh) = round24(wide_u(mr, mn as u32));
    usize::try_from(shift_floor(q, sh + er + en)).unwrap_or(usize::MAX)
}

/// `r / 16` as the nearest `f32` (ties to even), built from its bits.
#[inline]
fn sixteenths(r: u64) -> f32 {
    if r == 0 {
        return 0.0;
    }
    let (m, e) = round24(r);
    // m·2ᵉ with m in [2²³, 2²⁴) after the shift below; the f32 is m·2^(E - 150).
    let up = 24 - bits(m) as i32;
    let (m, e) = (m << up, e - up - 4);
    f32::from_bits((((e + 150) as u32) << 23) | (m as u32 & 0x7f_ffff))
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
    fn the_cortex_m0_routines_give_the_same_numbers() {
        for l in 1u32 << 13..1 << 15 {
            assert_eq!(reciprocal_by_newton(l), (1 << 29) / l, "{l}");
        }
        let mut x = 1u32 << 26;
        while x <= 3 << 28 {
            for y in [x, x + 1, x - 1] {
                assert_eq!(root_by_digits(y), root(y), "{y}");
                assert_eq!(root_by_table(y), root(y), "{y}");
            }
            let r = root(x);
            assert_eq!(root_by_digits(r * r), r);
            assert_eq!(root_by_digits(r * r - 1), r - 1);
            x += 4_999;
        }
        for x in (0..=u32::MAX).step_by(65_521).chain([0, 1, 2, 3, u32::MAX]) {
            assert_eq!(zeros_by_halving(x), x.leading_zeros(), "{x}");
            assert_eq!(root_by_digits(x), isqrt(u64::from(x)) as u32, "{x}");
        }
        let wides = [
            0u64,
            1,
            9,
            10,
            65_535,
            1 << 35,
            (1 << 38) + 12_345,
            u64::MAX,
        ];
        for a in wides {
            for d in [1u16, 2, 10, 7_919, u16::MAX] {
                assert_eq!(div_short(a, d), a / u64::from(d), "{a} / {d}");
            }
            for d in [1u32, 3, 10, 65_536, 1_000_003, u32::MAX] {
                assert_eq!(div_long(a, d), a / u64::from(d), "{a} / {d}");
            }
        }
        let edges = [
            0,
            1,
            -1,
            0xffff,
            0x1_0000,
            -0x1_0000,
            12_345_678,
            -98_765,
            i32::MAX,
            i32::MIN,
        ];
        for a in edges {
            for b in edges {
                assert_eq!(by_halves(a, b), i64::from(a) * i64::from(b), "{a} {b}");
                let (a, b) = (a as u32, b as u32);
                assert_eq!(by_halves_u(a, b), u64::from(a) * u64::from(b), "{a} {b}");
            }
        }
    }

    #[test]
    fn a_wide_normal_is_shifted_as_by_one_floor() {
        let reference = |v: [i64; 3]| {
            let m = v.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
            if m == 0 {
                return ([0; 3], 0);
            }
            let s = bits(m) as i32 - 14;
            (v.map(|x| (if s >= 0 { x >> s } else { x << -s }) as i32), s)
        };
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for k in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            // Magnitudes of every width up to 2⁴⁷, either sign; some of the form -(2ᵏ - 1).
            let w = 1 + k % 47;
            let f = |r: u64| {
                let m = (r & ((1 << w) - 1)) as i64;
                if r >> 63 == 1 {
                    -m
                } else {
                    m
                }
            };
            let v = [f(x), f(x.rotate_left(21)), -((1i64 << w) - 1)];
            assert_eq!(norm14(v), reference(v), "{v:?}");
        }
    }

    #[test]
    fn the_configuration_floats_are_read_as_the_float_operations_give_them() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let specials = [
            0.0f32,
            -0.0,
            1.0,
            0.7,
            0.1,
            0.5,
            1e-40,
            -0.3,
            f32::NAN,
            -f32::INFINITY,
        ];
        for k in 0..40_000 {
            // Every ratio a run takes (in [0, 1]), and NaN and negative ones.
            let r = match k % 4 {
                0 => (next() % 1001) as f32 / 1000.0,
                1 => f32::from_bits(next() as u32 % 0x3f80_0001),
                2 => -f32::from_bits(next() as u32 % 0x3f80_0001),
                _ => specials[k / 4 % specials.len()],
            };
            let n = match k % 3 {
                0 => (next() % 5000) as usize,
                1 => (next() % (1 << 26)) as usize,
                _ => next() as u32 as usize,
            };
            assert_eq!(ratio_of(r, n), (r * n as f32) as usize, "{r:e} x {n}");
            let e = next() >> (next() % 64);
            assert_eq!(sixteenths(e), e as f32 / 16.0, "{e}");
        }
        let grid = Grid::new(&[], 1);
        for d in [0.0f32, 1.0, 0.75, 3.5e-3, 1.5e9, 1e30] {
            let exact = (f64::from(d) * f64::from(d) * 256.0).floor();
            assert_eq!(grid.limit(d), (exact as u64).min(u64::MAX - 1), "{d}");
        }
        assert_eq!(grid.limit(f32::INFINITY), u64::MAX);
        assert_eq!(grid.limit(f32::NAN), u64::MAX);
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

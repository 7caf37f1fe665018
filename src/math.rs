//! The one math backend every floating-point function goes through.
//!
//! Determinism across x86-64 and every Cortex-M core depends on this: `f32` methods such as
//! `x.sqrt()` resolve to std's functions when std is linked (host tests) and to something else
//! on a device, and micromath's extension traits do the same. Here each function is called by
//! path, so the host and the device run the same code. Only `+ - * /` and bit operations are
//! used, which IEEE 754 and Rust define bit for bit (Rust never contracts them into FMA).
//!
//! Two backends: the default one here (1/√ from the bit-level guess and two Newton steps,
//! cosine from a polynomial: no library, no software `f64`, cheap on a Cortex-M0) and the
//! `micromath` feature (micromath's guess with one Newton step, and its cosine: faster, less
//! exact). The engine needs no square root at all otherwise.

/// `1/√x` for `x` in f32's normal range (callers guarantee it). Default backend: the
/// bit-level first guess and two Newton steps (relative error below 5e-6).
#[inline]
pub(crate) fn rsqrt(x: f32) -> f32 {
    let h = 0.5 * x;
    #[cfg(not(feature = "micromath"))]
    {
        let y = f32::from_bits(0x5f37_5a86u32.wrapping_sub(x.to_bits() >> 1));
        let y = y * (1.5 - h * y * y);
        y * (1.5 - h * y * y)
    }
    #[cfg(feature = "micromath")]
    {
        let y = micromath::F32(x).invsqrt().0;
        y * (1.5 - h * y * y)
    }
}

/// `√x` for `x ≥ 0` through [`rsqrt`] (0 below [`TINY2`] or for non-finite `x`).
#[inline]
pub(crate) fn sqrt(x: f32) -> f32 {
    if x > TINY2 && x.is_finite() {
        x * rsqrt(x)
    } else {
        0.0
    }
}

/// Cosine of an angle in degrees in `[0, 180]` (configuration only).
pub(crate) fn cos_deg(deg: f32) -> f32 {
    let x = deg * (core::f32::consts::PI / 180.0);
    #[cfg(not(feature = "micromath"))]
    {
        // cos x = 1 − 2 sin²(x/2), with sin on [0, π/2] from its Taylor series to x¹¹
        // (error below 1e-7 there).
        let h = 0.5 * x;
        let h2 = h * h;
        let s = h
            * (1.0
                - h2 / 6.0
                    * (1.0
                        - h2 / 20.0 * (1.0 - h2 / 42.0 * (1.0 - h2 / 72.0 * (1.0 - h2 / 110.0)))));
        1.0 - 2.0 * s * s
    }
    #[cfg(feature = "micromath")]
    {
        micromath::F32(x).cos().0
    }
}

/// Below this a squared length is treated as zero (no direction): well inside f32's normal
/// range, so [`rsqrt`] never sees a subnormal.
pub(crate) const TINY2: f32 = 1e-30;

/// The power of two `k` with `m·k` in `[1, 2)`, for a positive normal `m`; zero for zero, a
/// subnormal, infinity or NaN (no direction worth keeping). Scaling by it is exact.
#[inline]
pub(crate) fn pow2_inverse(m: f32) -> f32 {
    if m.is_nan() || m < f32::MIN_POSITIVE || !m.is_finite() {
        return 0.0;
    }
    let e = (m.to_bits() >> 23) as i32 - 127;
    // 2^-e; for e = 127 that is 2^-127, a subnormal power of two: the product is still exact.
    if e < 127 {
        f32::from_bits(((127 - e) as u32) << 23)
    } else {
        f32::from_bits(0x0040_0000)
    }
}

/// `v` scaled by a power of two (exact) so that its largest component lies in `[1, 2)`; zero
/// stays zero. Directions of tiny or huge vectors survive squaring this way: a cross product
/// of edges near 1e-20 long would otherwise underflow (found by fuzzing).
#[inline]
pub(crate) fn pow2_normalize(v: V3) -> V3 {
    let mut v = v;
    let mut m = max_abs(v);
    // A subnormal largest component: lift by 2^64 first (exact).
    if m > 0.0 && m < f32::MIN_POSITIVE {
        let k = f32::from_bits((127 + 64) << 23);
        v = scale(v, k);
        m *= k;
    }
    scale(v, pow2_inverse(m))
}

pub(crate) type V3 = [f32; 3];

#[inline]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub(crate) fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn scale(a: V3, s: f32) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Largest absolute component.
#[inline]
pub(crate) fn max_abs(a: V3) -> f32 {
    let m = if a[0].abs() > a[1].abs() {
        a[0].abs()
    } else {
        a[1].abs()
    };
    if a[2].abs() > m {
        a[2].abs()
    } else {
        m
    }
}

/// Unit vector of a vector with squared length `l2` (zero if tiny).
#[inline]
pub(crate) fn unit_of(v: V3, l2: f32) -> V3 {
    if l2 > TINY2 && l2.is_finite() {
        scale(v, rsqrt(l2))
    } else {
        [0.0; 3]
    }
}

/// Squared distance from `p` to the segment `a`-`b`.
pub(crate) fn segment_distance2(p: V3, a: V3, b: V3) -> f32 {
    let ab = sub(b, a);
    let ap = sub(p, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        let t = dot(ap, ab) / l2;
        // Written out rather than `clamp`, which has a panic path for NaN bounds.
        if t > 1.0 {
            1.0
        } else if t > 0.0 {
            t
        } else {
            0.0
        }
    } else {
        0.0
    };
    let d = sub(ap, scale(ab, t));
    dot(d, d)
}

#[cfg(test)]
mod tests {
    #[test]
    fn cosine_of_degrees_matches_f64() {
        for d in 0..=180 {
            let c = super::cos_deg(d as f32);
            let want = (d as f64).to_radians().cos();
            let tol = if cfg!(feature = "micromath") {
                2e-3
            } else {
                2e-5
            };
            assert!((c as f64 - want).abs() < tol, "{d}: {c} vs {want}");
        }
    }

    #[test]
    fn rsqrt_is_close() {
        for i in 1..1000 {
            let x = i as f32 * 0.37;
            let r = super::rsqrt(x) as f64;
            let want = 1.0 / (x as f64).sqrt();
            assert!((r / want - 1.0).abs() < 2e-3, "{x}");
        }
    }
}

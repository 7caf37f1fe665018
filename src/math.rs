//! The one math backend every floating-point function goes through.
//!
//! Determinism across x86-64 and every Cortex-M core depends on this: `f32` methods such as
//! `x.sqrt()` resolve to std's functions when std is linked (host tests) and to something else
//! on a device, and micromath's extension traits do the same. Here each function is called by
//! path, so the host and the device run the same code: libm (correctly rounded `sqrtf`, the
//! default) or micromath (fast approximations, feature `micromath`). Only `+ - * /` are used
//! elsewhere, which IEEE 754 defines bit for bit, and Rust never contracts them into FMA.

/// `1/√x` for `x` in f32's normal range (callers guarantee it), from `+ - *` only: the
/// bit-level first guess and two Newton steps (relative error below 5e-6). The same bits on
/// every target, and cheap where `sqrtf` is a software routine (a Cortex-M0 has no FPU;
/// libm's `sqrtf` costs about 60 instructions even on an M4F).
#[inline]
pub(crate) fn rsqrt(x: f32) -> f32 {
    let y = f32::from_bits(0x5f37_5a86u32.wrapping_sub(x.to_bits() >> 1));
    let h = 0.5 * x;
    let y = y * (1.5 - h * y * y);
    y * (1.5 - h * y * y)
}

/// Below this a squared length is treated as zero (no direction): well inside f32's normal
/// range, so [`rsqrt`] never sees a subnormal.
pub(crate) const TINY2: f32 = 1e-30;

/// The power of two `k` with `m·k` in `[1, 2)`, for a positive normal `m`; zero for zero, a
/// subnormal, infinity or NaN (no direction worth keeping). Scaling by it is exact.
#[inline]
pub(crate) fn pow2_inverse(m: f32) -> f32 {
    if !(m >= f32::MIN_POSITIVE) || !m.is_finite() {
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

/// Cosine of an angle in radians.
#[inline]
pub(crate) fn cos(x: f32) -> f32 {
    #[cfg(feature = "micromath")]
    {
        micromath::F32(x).cos().0
    }
    #[cfg(not(feature = "micromath"))]
    {
        libm::cosf(x)
    }
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

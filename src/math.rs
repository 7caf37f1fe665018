//! The one math backend every floating-point function goes through.
//!
//! Determinism across x86-64 and every Cortex-M core depends on this: `f32` methods such as
//! `x.sqrt()` resolve to std's functions when std is linked (host tests) and to something else
//! on a device, and micromath's extension traits do the same. Here each function is called by
//! path, so the host and the device run the same code: libm (correctly rounded `sqrtf`, the
//! default) or micromath (fast approximations, feature `micromath`). Only `+ - * /` are used
//! elsewhere, which IEEE 754 defines bit for bit, and Rust never contracts them into FMA.

/// Square root.
#[inline]
pub(crate) fn sqrt(x: f32) -> f32 {
    #[cfg(feature = "micromath")]
    {
        micromath::F32(x).sqrt().0
    }
    #[cfg(not(feature = "micromath"))]
    {
        libm::sqrtf(x)
    }
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

/// `v / m` for `m > 0`: one reciprocal and three products, or three divisions when `1 / m`
/// would overflow (a subnormal `m`). The branch depends only on the data, so every target
/// takes the same one.
#[inline]
pub(crate) fn div(v: V3, m: f32) -> V3 {
    let k = 1.0 / m;
    if k.is_finite() {
        scale(v, k)
    } else {
        [v[0] / m, v[1] / m, v[2] / m]
    }
}

/// Unit vector, or zero for a zero vector (a zero-area triangle has no direction).
///
/// Divided by its largest component before squaring: the squared length of a tiny but valid
/// normal (a mesh dwarfed by one stray vertex has cross products near 1e-22) would otherwise
/// fall below f32's normal range and lose its direction (found by fuzzing).
#[inline]
pub(crate) fn unit(a: V3) -> V3 {
    let m = max_abs(a);
    if m > 0.0 {
        let b = div(a, m);
        scale(b, 1.0 / sqrt(dot(b, b)))
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

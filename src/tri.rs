//! Index triples, shared by the mesh, the progressive mesh and the stream: the slot order of a
//! triangle's corners, the end-of-list marker, and the two rules that drop an input triangle
//! before simplifying (the simplifier and the progressive mesh must drop the same ones; each
//! walks its own lists for the earlier triangles).

/// Where two lists of triangles differ: the shorter one's length if their lengths differ, else
/// the first triangle that differs, `None` if they are equal (a bound's original triangles
/// against the ones to simplify).
pub(crate) fn first_difference<T: PartialEq>(a: &[[T; 3]], b: &[[T; 3]]) -> Option<usize> {
    if a.len() != b.len() {
        return Some(a.len().min(b.len()));
    }
    a.iter().zip(b).position(|(x, y)| x != y)
}

/// Marks the end of a list, or "no vertex".
pub(crate) const NIL: usize = usize::MAX;

/// The slot after `k` in winding order (a corner's `a`).
#[inline]
pub(crate) const fn next3(k: usize) -> usize {
    // Written so that the result is below 3 for any `k`: indexing with it needs no check.
    match k {
        0 => 1,
        1 => 2,
        _ => 0,
    }
}

/// The slot before `k` in winding order (a corner's `b`).
#[inline]
pub(crate) const fn prev3(k: usize) -> usize {
    match k {
        1 => 0,
        2 => 1,
        _ => 2,
    }
}

/// The two vertices after slot `k` (0, 1 or 2) of `t` in winding order: `(t[next3(k)],
/// t[prev3(k)])`, by a match on `k` (indexing with a computed slot spilled the triangle to the
/// stack). A corner's slot is never 3; it would read as 2.
#[inline(always)]
pub(crate) fn others<T: Copy>(t: [T; 3], k: usize) -> (T, T) {
    let [a, b, c] = t;
    match k {
        0 => (b, c),
        1 => (c, a),
        _ => (a, b),
    }
}

/// Same three vertices (any order or winding): a later copy of a kept triangle is dropped.
/// Both directions, so a removed `[x, x, x]` never matches.
pub(crate) fn same_set(a: [usize; 3], b: [usize; 3]) -> bool {
    a.iter().all(|x| b.contains(x)) && b.iter().all(|x| a.contains(x))
}

/// Whether `b` is `a` with the same winding (a rotation of it); with [`same_set`] false, `b` is
/// `a` turned over.
#[inline]
pub(crate) fn same_winding(a: [usize; 3], b: [usize; 3]) -> bool {
    // Element by element: array `==` is a `memcmp` call per rotation on a Cortex-M.
    let [x, y, z] = a;
    (b[0] == x && b[1] == y && b[2] == z)
        || (b[0] == y && b[1] == z && b[2] == x)
        || (b[0] == z && b[1] == x && b[2] == y)
}

/// An input triangle with a repeated index: dropped.
#[inline]
pub(crate) fn is_degenerate([a, b, c]: [usize; 3]) -> bool {
    a == b || b == c || a == c
}

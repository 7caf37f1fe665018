//! A vertex split's connectivity as both ends derive it: the triangles that stay with the kept
//! vertex, the wings, and the fan run of mode 0.

use crate::index::Index;
use crate::progressive::Lists;
use crate::tri::{next3, prev3};

/// The triangles of `s`'s list that stay with `s` in a split moving the `moved` ones.
pub(super) fn staying<'l, I: Index>(
    lists: &'l Lists<'_, I>,
    s: usize,
    moved: u64,
) -> impl Iterator<Item = [usize; 3]> + 'l {
    let mut c = lists.first(s);
    let mut p = 0u32;
    core::iter::from_fn(move || {
        while c != usize::MAX && p as usize <= lists.tris.len() {
            let here = c;
            let pos = p;
            c = lists.after(c, s);
            p += 1;
            if pos < 64 && moved & (1u64 << (pos & 63)) != 0 {
                continue;
            }
            return lists.tris.get(here).map(|x| x.map(|i| i.to_usize()));
        }
        None
    })
}

/// The wing `w` that triangle `ct` (holding `s`) offers a restored triangle whose `t` follows
/// `s` (`t_next`) or precedes it: the neighbour across edge `s-w` runs it the other way.
pub(super) fn wing(ct: [usize; 3], s: usize, t_next: bool) -> Option<usize> {
    let k = ct.iter().position(|&x| x == s)?;
    Some(if t_next { ct[next3(k)] } else { ct[prev3(k)] })
}

/// Marks "no vertex".
pub(super) const NONE: usize = usize::MAX;

/// Restored triangle with `s` in slot `ks`, `t` after it (`t_next`) or before it, and `w` in
/// the third slot; `None` if that is not a triangle of three distinct vertices below `t + 1`.
pub(super) fn arrange<I: Index>(
    ks: usize,
    t_next: bool,
    s: usize,
    t: usize,
    w: usize,
) -> Option<[I; 3]> {
    if ks > 2 || w >= t || w == s || s >= t {
        return None;
    }
    let (kt, kw) = if t_next {
        (next3(ks), prev3(ks))
    } else {
        (prev3(ks), next3(ks))
    };
    let mut v = [0usize; 3];
    for (k, x) in v.iter_mut().enumerate() {
        *x = if k == ks {
            s
        } else if k == kt {
            t
        } else if k == kw {
            w
        } else {
            0
        };
    }
    Some(v.map(I::narrow))
}

/// The fan run (mode 0 of a split): the staying triangle at place `q1` of `s`'s list names the
/// wing `w1`; the `k` moved triangles are the ones met walking around `s` from edge `s-w1`
/// away from that triangle (a collapse put the removed vertex's fan there, between its two
/// wings). Returns the moved mask, `w1`, and the far vertex of the last moved triangle (the
/// second wing). `None` if the walk leaves the list or passes position 63.
pub(super) fn fan_run<I: Index>(
    lists: &Lists<'_, I>,
    s: usize,
    q1: usize,
    t_next: bool,
    k: usize,
) -> Option<(u64, usize, Option<usize>)> {
    let w1 = wing(staying(lists, s, 0).nth(q1)?, s, t_next)?;
    let mut mask = 0u64;
    let mut x = w1;
    let mut last = None;
    for _ in 0..k {
        let (p, ct, ks) = staying(lists, s, 0).enumerate().find_map(|(p, ct)| {
            let ks = ct.iter().position(|&v| v == s)?;
            let near = if t_next { ct[prev3(ks)] } else { ct[next3(ks)] };
            let free = p < 64 && mask & (1u64 << (p & 63)) == 0;
            (near == x && free).then_some((p, ct, ks))
        })?;
        mask |= 1u64 << (p & 63);
        x = if t_next { ct[next3(ks)] } else { ct[prev3(ks)] };
        last = Some(x);
    }
    Some((mask, w1, last))
}

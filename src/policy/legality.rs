//! Which collapses keep the mesh valid: the legality rules, declared once, in [`RULES`].
//!
//! A half-edge collapse `a -> b` (a moves onto b, b stays where it is, or moves to the cost's
//! placement) is refused when any rule fails. Each rule is one row of [`RULES`]: the
//! [`Reject`] it is counted under, its name (the report's label and its build-time switch),
//! what it protects, its [`Kind`] and its source. The report's counts
//! ([`Rejections`](crate::Rejections)), the host tools' reports, the QEMU result files, the
//! golden files, `tests/rules.rs` and `scripts/rules-off.sh` all read this table; none of them
//! lists the rules again.
//!
//! # Kinds
//!
//! - **validity** (`locked`, `boundary`, `link`, `duplicate`, `fold`): without the rule the
//!   output can stop being a valid mesh of the same topology (a non-manifold edge, a pinched
//!   vertex, a duplicate or folded triangle, a boundary loop closed or left).
//! - **validity and quality** (`sliver`): a triangle of zero area, or so thin that rounding
//!   decides which way it faces, is always refused (validity); one whose quality falls below
//!   [`Config::min_quality`] is refused only when it also got worse *and* left its plane (a
//!   preference). A collapse that keeps a flat face flat is never refused for its slivers: on a
//!   flat CAD face the triangles are long fans into holes and corners, nearly every collapse
//!   there makes a thinner triangle, and a veto on them left only the expensive collapses
//!   (corners, holes) to reach the count. Such a sliver costs no error and a later collapse
//!   can remove it; meshoptimizer has no shape veto at all (only its flip test), VCG's quality
//!   check is a soft penalty.
//! - **quality** (`feature`, `normal_turn`, `seam`): the output stays valid without them; they
//!   keep the feature vertices of Lin Mouguang 2007, bound how far a triangle may turn in one
//!   collapse ([`Config::max_normal_turn_deg`]), and with welded seams (module `seam`, crate
//!   feature `seams`) keep a seam where it is, so that no triangle takes attributes from both
//!   of its sides (meshoptimizer's vertex kinds: a seam vertex moves along its seam; a vertex
//!   where more than two wedges meet stays, like its complex kind, or with
//!   `seam::SeamCorners::Move` moves all of them).
//! - **guarantee** (`bound`): the error bound of Zhu, Wang and Meng 2007, a promise the caller
//!   asks for ([`Config::max_error`]); checked after the others, in `collapse`, and only on the
//!   bounded entry points (see [`crate::bound`]).
//!
//! # Order
//!
//! The engine keys vertices by cost alone and runs the rules only when a vertex reaches the
//! top of the queue, on its candidates in cost order. The rules, in the order they are
//! checked: the cheap flag tests (`locked`, `feature`), `seam` (welded runs) and `boundary`; then, triangle by
//! triangle of a's fan, `duplicate`, `sliver`, `normal_turn` and `fold`; last the link
//! condition's walks of both fans (`link`), the folds across b's edges to o1 and o2, whose
//! triangles that walk finds, and the error bound. On flat, sliver-rich (CAD) meshes most
//! candidates fail a shape rule, so they never pay for the walks (figures in docs/speed.md). A
//! refusal is counted under the first
//! rule that fails, so the order shapes [`Report::rejected`](crate::Report::rejected), never
//! the verdict. The table's order is the report's, not the checking order.
//!
//! Interior vertices may move onto boundary vertices (the boundary does not change), never the
//! reverse. Together with the link condition this keeps a closed manifold closed, keeps the
//! Euler characteristic and the number of boundary loops, and never creates a non-manifold edge.
//!
//! No square root anywhere: angles are compared as `dot² ≶ cos²·|n₁|²·|n₂|²` on normals scaled
//! by powers of two (exact), which is both cheaper and scale-safe.
//!
//! # Switching a rule off
//!
//! Building with the environment variable `TINYDECIMATE_RULE_OFF` set to one rule's name
//! switches that rule off, so that `scripts/rules-off.sh` (which reads the names from this
//! table) can show that the test suite fails without each of them. A name that is not in the
//! table is a build error. The switches are constants (`on!(Rule)` is `const { .. }` over the
//! table), so a normal build carries no trace of them.
//!
//! # Adding a rule
//!
//! 1. a [`Reject`] variant and its row in [`RULES`], at the same position (a row out of
//!    place, or a variant without a row that `on!` names, is a build error);
//! 2. its function, called where it belongs in the order above, under `on!(Variant)`;
//! 3. its test: a property of real output it keeps, in `tests/rules.rs`, listed in that file's
//!    table (a test there fails when a rule of [`RULES`] has no row).
//!
//! Everything that counts or prints rejections iterates the table and follows: the report,
//! `host-sim simplify` and `bench`, the QEMU result file (room for 16 rules,
//! `meshfmt::REJECTION_SLOTS`), the golden files' text and `scripts/rules-off.sh`. What else
//! changes, only when it applies: a rule with a limit needs its [`Config`] field, checked in
//! `Config::validate` under a new `ConfigField`, and a field of the QEMU case file if golden
//! cases set it; a rule on vertex flags (like `locked` and `feature`) also belongs in the
//! queue's filters in `collapse` (`skip`, `rekey`), which keep such vertices out of the queue;
//! and the golden files' `.txt` show one more count, so they are re-blessed once
//! (`host-sim golden --bless`; the `.bin` outputs change only if the rule refuses something).

use crate::index::Index;
use crate::math::{self, V3};
use crate::mesh::{corner, flag, next3, prev3, Mesh, NIL};
use crate::Config;

/// Why a candidate collapse was refused: one variant per rule, in the order of [`RULES`],
/// whose row says what the rule protects. The engine counts each in
/// [`Rejections`](crate::Rejections).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reject {
    /// An endpoint is locked.
    Locked,
    /// An endpoint is a feature vertex.
    Feature,
    /// A boundary rule fails.
    Boundary,
    /// The link condition fails.
    Link,
    /// The collapse would create a triangle that already exists.
    Duplicate,
    /// A remaining triangle's normal would turn too far.
    NormalTurn,
    /// A triangle would become zero-area or a sliver.
    Sliver,
    /// Two adjacent triangles would fold onto each other.
    Fold,
    /// A control point would end too far from the new fan.
    Bound,
    /// A seam vertex would leave its seam.
    Seam,
}

impl Reject {
    /// How many rules there are: the length of [`RULES`].
    pub const COUNT: usize = RULES.len();

    /// This rule's row of [`RULES`].
    pub const fn rule(self) -> &'static Rule {
        &RULES[self as usize]
    }

    /// This rule's name ([`Rule::name`]).
    pub const fn name(self) -> &'static str {
        self.rule().name
    }
}

/// What a rule is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A hard rule: without it the output can stop being a valid mesh of the same topology.
    Validity,
    /// A validity part and a preference: zero area is always refused, a quality below the
    /// limit only when it got worse.
    ValidityAndQuality,
    /// A preference: the output stays valid without it.
    Quality,
    /// A guarantee the caller asks for (the error bound).
    Guarantee,
}

/// One legality rule: a row of [`RULES`].
#[derive(Clone, Copy, Debug)]
pub struct Rule {
    /// What a refusal by this rule is counted under; its position in [`RULES`].
    pub reject: Reject,
    /// The rule's name: its label in reports and files, and its build-time switch
    /// (`TINYDECIMATE_RULE_OFF=<name>`).
    pub name: &'static str,
    /// When it refuses a collapse, and so what it protects.
    pub protects: &'static str,
    /// Hard validity rule, quality preference or guarantee.
    pub kind: Kind,
    /// Where the rule comes from (empty: this library's own).
    pub source: &'static str,
}

/// The legality rules, one row each, in the order of [`Reject`] (the report's order; the
/// checking order is in the module documentation).
pub const RULES: &[Rule] = &[
    Rule {
        reject: Reject::Locked,
        name: "locked",
        protects: "a is on a non-manifold edge, a pinched fan or an inconsistently wound \
                   edge, or b is and a is on the boundary or b's edge to o1 or o2 is \
                   non-manifold: irregular vertices never move (an interior vertex may move \
                   onto one)",
        kind: Kind::Validity,
        source: "Cheng, Pan and Shi §3.1 (irregular vertices)",
    },
    Rule {
        reject: Reject::Feature,
        name: "feature",
        protects: "a is a feature vertex, or b is one and feature targets are not allowed: \
                   features survive",
        kind: Kind::Quality,
        source: "Lin Mouguang 2007 §3.3",
    },
    Rule {
        reject: Reject::Boundary,
        name: "boundary",
        protects: "a is on the boundary and a-b is not a boundary edge, or the boundary loop \
                   through a-b has only three edges: boundaries only shrink along themselves",
        kind: Kind::Validity,
        source: "Cheng, Pan and Shi §3.2(1), second and third conditions",
    },
    Rule {
        reject: Reject::Link,
        name: "link",
        protects: "a vertex adjacent to both a and b is not opposite a-b: the surface would \
                   pinch or gain a non-manifold edge",
        kind: Kind::Validity,
        source: "Cheng, Pan and Shi §3.2(1), first condition (the link condition)",
    },
    Rule {
        reject: Reject::Duplicate,
        name: "duplicate",
        protects: "a triangle of a would become a copy of one of b's",
        kind: Kind::Validity,
        source: "",
    },
    Rule {
        reject: Reject::NormalTurn,
        name: "normal_turn",
        protects: "a surviving triangle's normal turns by more than \
                   Config::max_normal_turn_deg",
        kind: Kind::Quality,
        source: "Cheng, Pan and Shi §3.2(2), the dihedral threshold",
    },
    Rule {
        reject: Reject::Sliver,
        name: "sliver",
        protects: "a surviving triangle gets zero area or a normal that rounding decides \
                   (validity), or leaves its plane with a quality below Config::min_quality \
                   that is also worse than before (preference)",
        kind: Kind::ValidityAndQuality,
        source: "",
    },
    Rule {
        reject: Reject::Fold,
        name: "fold",
        protects: "a surviving triangle and a neighbour across any of its edges end up with \
                   nearly opposite normals (more than about 154° apart)",
        kind: Kind::Validity,
        source: "Cheng, Pan and Shi §3.2(2)",
    },
    Rule {
        reject: Reject::Bound,
        name: "bound",
        protects: "a control point would end farther than Config::max_error from every \
                   triangle of the new fan (bounded entry points only)",
        kind: Kind::Guarantee,
        source: "Zhu, Wang and Meng 2007 §3",
    },
    Rule {
        reject: Reject::Seam,
        name: "seam",
        protects: "with welded seams (crate::seam): a on a seam (its wedge changes across one \
                   or two spokes) moves only along that seam, so the seam keeps its shape and \
                   no triangle takes corners from both sides, and never takes a chart's (a \
                   material's) last triangle (welded runs only)",
        kind: Kind::Quality,
        source: "meshoptimizer's vertex kinds (a Seam vertex collapses along its seam)",
    },
];

// Row i is `Reject` variant i, and names are distinct (they are switches and labels).
const _: () = {
    let mut i = 0;
    while i < RULES.len() {
        assert!(
            RULES[i].reject as usize == i,
            "RULES is not in the order of Reject"
        );
        let mut j = 0;
        while j < i {
            assert!(
                !same(RULES[i].name, RULES[j].name),
                "two rules share a name"
            );
            j += 1;
        }
        i += 1;
    }
};

/// The rule switched off in this build (`TINYDECIMATE_RULE_OFF`), or `""`.
const OFF: &str = match option_env!("TINYDECIMATE_RULE_OFF") {
    Some(s) => s,
    None => "",
};

/// Whether two strings are equal (in a `const fn`).
const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

// A switch that names no rule would silently test nothing.
const _: () = {
    let mut known = OFF.is_empty();
    let mut i = 0;
    while i < RULES.len() {
        known |= same(OFF, RULES[i].name);
        i += 1;
    }
    assert!(
        known,
        "TINYDECIMATE_RULE_OFF names no rule of legality::RULES"
    );
};

/// Whether rule `r` is on in this build: every rule, unless `TINYDECIMATE_RULE_OFF` names it.
/// Used through [`on!`], which evaluates it at compile time.
pub(crate) const fn is_on(r: Reject) -> bool {
    !same(OFF, r.name())
}

/// `on!(Fold)`: whether the rule of `Reject::Fold` is on in this build, a constant.
macro_rules! on {
    ($rule:ident) => {
        const { $crate::legality::is_on($crate::Reject::$rule) }
    };
}
pub(crate) use on;

/// Two adjacent triangles whose unit normals have a dot product below −0.89 are folded onto
/// each other (more than about 153° apart); compared squared. The shared checker's limit is
/// −0.9 in `f64`: the margin covers the rounding of `f32` normals of small triangles far from
/// the origin, so that no pair this test passes is one the checker calls folded.
const FOLD_DOT2: f32 = 0.89 * 0.89;

/// A triangle whose normal turns by less than this (cosine of about 1°) stays in its plane:
/// a sliver there costs no error, so the sliver preference does not apply.
const COS_PLANAR: f32 = 0.999_85;
const COS_PLANAR2: f32 = COS_PLANAR * COS_PLANAR;

/// Below this quality (`|n|² / (Σ edge²)²`: a height about 10⁻⁴ of the longest edge) a
/// triangle's normal is at the mercy of rounding, so it could flip unseen: it counts as zero
/// area, unless it was already that thin.
const FLAT: f32 = 1e-8;

/// The geometric limits of a [`Config`], precomputed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rules {
    cos_turn: f32,
    cos_turn2: f32,
    /// `min_quality² / 12`, compared with `|n|² / (Σ edge²)²`.
    min_ratio: f32,
    pub(crate) feature_targets: bool,
}

impl Rules {
    pub(crate) fn new(config: &Config) -> Self {
        let q = config.min_quality;
        let c = math::cos_deg(config.max_normal_turn_deg);
        Rules {
            cos_turn: c,
            cos_turn2: c * c,
            min_ratio: q * q / 12.0,
            // The paper's schedule keeps the paper's rule.
            feature_targets: config.feature_targets && config.schedule.is_ordered(),
        }
    }
}

/// What the rules need of one triangle.
#[derive(Clone, Copy)]
pub(crate) struct Shape {
    /// The normal (cross product of the edges), scaled by a power of two to a largest
    /// component in `[1, 2)`; zero if the triangle has no area.
    n: V3,
    /// `|n|²`.
    n2: f32,
    /// quality² / 12 = |cross|² / (Σ edge²)², scale-free; 1/12 for an equilateral triangle.
    quality: f32,
}

impl Shape {
    /// The shape of triangle `p`, computed on its edges scaled by a power of two (exact), so
    /// that neither squares nor products of tiny or huge edges leave f32's normal range.
    #[inline]
    pub(crate) fn of(p: [V3; 3]) -> Shape {
        let e = [
            math::sub(p[1], p[0]),
            math::sub(p[2], p[1]),
            math::sub(p[0], p[2]),
        ];
        let m = math::max_abs(e[0])
            .max(math::max_abs(e[1]))
            .max(math::max_abs(e[2]));
        // Subnormal edges (coordinates near zero): lift them by 2^64 first (exact), so that
        // their triangles keep a direction and folds against them are still seen.
        let (e, m) = if m > 0.0 && m < f32::MIN_POSITIVE {
            let lift = f32::from_bits((127 + 64) << 23);
            (e.map(|v| math::scale(v, lift)), m * lift)
        } else {
            (e, m)
        };
        let k = math::pow2_inverse(m);
        if k == 0.0 {
            return Shape {
                n: [0.0; 3],
                n2: 0.0,
                quality: 0.0,
            };
        }
        let e = e.map(|v| math::scale(v, k));
        // cross(p1 - p0, p2 - p0), with p2 - p0 = -e2.
        let c = math::cross(e[0], math::scale(e[2], -1.0));
        let l2 = math::dot(c, c);
        let s = math::dot(e[0], e[0]) + math::dot(e[1], e[1]) + math::dot(e[2], e[2]);
        let n = math::pow2_normalize(c);
        Shape {
            n,
            n2: math::dot(n, n),
            quality: if s > 0.0 { l2 / (s * s) } else { 0.0 },
        }
    }

    /// The unit normal (zero if no area).
    #[inline]
    pub(crate) fn unit(&self) -> V3 {
        math::unit_of(self.n, self.n2)
    }
}

/// The sliver and normal-turn rules on one surviving triangle, `was` before the collapse and
/// `now` after it. One dot product serves both: the turn limit and the plane test (a sliver
/// that stays within about 1° of its plane is allowed).
#[inline(never)]
fn shape_rules(rules: &Rules, was: &Shape, now: &Shape) -> Result<(), Reject> {
    let d = math::dot(was.n, now.n);
    let (d2, n2) = (d * d, was.n2 * now.n2);
    // Whether the angle between the normals exceeds the one whose cosine is `cos`.
    let turned = |cos: f32, cos2: f32| {
        if cos >= 0.0 {
            d < 0.0 || d2 < cos2 * n2
        } else {
            d < 0.0 && d2 > cos2 * n2
        }
    };
    let q = now.quality;
    if on!(Sliver)
        && (q <= 0.0
            || (q < was.quality
                && (q < FLAT || (q < rules.min_ratio && turned(COS_PLANAR, COS_PLANAR2)))))
    {
        return Err(Reject::Sliver);
    }
    // A zero-area triangle has no direction to turn from.
    if on!(NormalTurn) && was.quality > 0.0 && turned(rules.cos_turn, rules.cos_turn2) {
        return Err(Reject::NormalTurn);
    }
    Ok(())
}

/// Whether two triangles sharing an edge are folded onto each other.
#[inline]
fn folded(u: &Shape, v: &Shape) -> bool {
    let d = math::dot(u.n, v.n);
    d < 0.0 && d * d > FOLD_DOT2 * u.n2 * v.n2
}

/// The shape of live triangle `t`.
#[inline]
fn shape_of<L: Index, I: Index>(mesh: &Mesh<'_, L, I>, t: usize) -> Shape {
    Shape::of(mesh.tri(t).map(|v| mesh.p(v)))
}

/// The flag rules alone: whether `a` may move at all, and onto a vertex with flags `fb`.
///
/// A locked vertex never moves, but an interior vertex may move onto it (meshoptimizer's
/// kinds table lets a manifold vertex collapse onto a complex or locked one): the locked
/// vertex keeps its irregular fans as they were, one of them takes `a`'s disc in, and the link
/// condition, which then marks every neighbour of the locked vertex, refuses a collapse that
/// would join two of its fans or add a triangle on one of its non-manifold edges.
#[inline]
pub(crate) fn flags_allow(rules: &Rules, fa: u8, fb: u8) -> Result<(), Reject> {
    if fa & fb & flag::USED == 0
        || (on!(Locked)
            && (fa & flag::LOCKED != 0 || (fb & flag::LOCKED != 0 && fa & flag::BOUNDARY != 0)))
    {
        return Err(Reject::Locked);
    }
    if on!(Feature)
        && (fa & flag::FEATURE != 0 || (fb & flag::FEATURE != 0 && !rules.feature_targets))
    {
        return Err(Reject::Feature);
    }
    Ok(())
}

/// The shape of live triangle `t` once `a` and `b` are both at `p` (`b` moved, `a` merged
/// into it).
#[inline]
fn shape_moved<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    t: usize,
    a: usize,
    b: usize,
    p: V3,
) -> Shape {
    Shape::of(
        mesh.tri(t)
            .map(|v| if v == a || v == b { p } else { mesh.p(v) }),
    )
}

/// The triangle across edge `x-y` from live triangle `t`, whose slot `ky` holds `y` and whose
/// next slot holds `x` (`t` is `(y, ·, x)` read from `y`), found in O(1) from `y`'s fan order:
/// the triangle after `t` in `y`'s list is the one across `y-x` (see `mesh`). `Some(None)`:
/// `x-y` is a boundary edge. `None`: `y`'s list is not in fan order (a locked vertex) or does
/// not answer as fan order would; the caller then searches `x`'s triangles.
#[inline]
fn outer<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    t: usize,
    ky: usize,
    x: usize,
    y: usize,
) -> Option<Option<usize>> {
    let fy = mesh.flags(y);
    if fy & flag::LOCKED != 0 {
        return None;
    }
    let mut n = mesh.after(corner(t, ky));
    if n == NIL {
        if fy & flag::BOUNDARY != 0 {
            // y's last triangle: its edge y-x has no twin.
            return Some(None);
        }
        // An interior fan is a cycle; its list starts anywhere.
        n = mesh.first(y);
    }
    let u = n >> 2;
    let tri = mesh.tri(u);
    if u != t && tri.get(next3(n & 3)) == Some(&x) {
        Some(Some(u))
    } else {
        None
    }
}

/// The rules on one surviving triangle `t` (vertices `old`) of a moved vertex's fan (the
/// vertex in slot `k`, moved to `p`): its own shape and turn, and folds against the survivor
/// before it in fan order (`prev`: its `y` and shape after the move; a fold across the spoke
/// when that `y` is this one's `x`) and against the triangle across its outer edge `x-y`
/// (`after`: a triangle's shape after the collapse). Returns its shape after the move. Shared
/// by a's triangles ([`check`]) and b's ([`check_moved_b`]).
#[inline(always)]
fn survivor<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    rules: &Rules,
    (t, k, old): (usize, usize, [usize; 3]),
    p: V3,
    prev: Option<(usize, Shape)>,
    after: &impl Fn(usize) -> Shape,
) -> Result<Shape, Reject> {
    let (x, y) = crate::tri::others(old, k);
    let q = old.map(|v| mesh.p(v));
    let mut r = q;
    if let Some(v) = r.get_mut(k) {
        *v = p;
    }
    let was = Shape::of(q);
    let now = Shape::of(r);
    shape_rules(rules, &was, &now)?;
    if on!(Fold) {
        let mut fold = false;
        if let Some((py, ps)) = prev {
            fold |= py == x && folded(&ps, &now);
        }
        // Outer edge x-y: every other triangle holding both (one, on a manifold edge).
        match outer(mesh, t, prev3(k), x, y) {
            Some(Some(u)) => fold |= folded(&now, &after(u)),
            Some(None) => {}
            None => {
                for (u, _) in mesh.corners(x) {
                    if u != t && mesh.tri(u).contains(&y) {
                        fold |= folded(&now, &after(u));
                    }
                }
            }
        }
        if fold {
            return Err(Reject::Fold);
        }
    }
    Ok(now)
}

/// Checks every rule for `a -> b`; with `at`, the rules on `a`'s triangles for `b` moved to
/// `at` (optimal placement; [`check_placed`] adds `b`'s own triangles, which change too).
pub(crate) fn check<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    rules: &Rules,
    a: usize,
    b: usize,
    at: Option<V3>,
) -> Result<(), Reject> {
    // The shape after the collapse of a triangle that is not a's.
    let after = |u: usize| match at {
        None => shape_of(mesh, u),
        Some(p) => shape_moved(mesh, u, a, b, p),
    };
    let fa = mesh.flags(a);
    flags_allow(rules, fa, mesh.flags(b))?;
    #[cfg(feature = "seams")]
    if on!(Seam) && !mesh.wedges.is_empty() && !along_seam(mesh, a, b) {
        return Err(Reject::Seam);
    }

    // The vertices opposite edge a-b: o1 in (a, b, o1), o2 in (a, o2, b).
    let (mut o1, mut o2, mut n_ab) = (NIL, NIL, 0);
    for (t, k) in mesh.corners(a) {
        let tri = mesh.tri(t);
        let (x, y) = crate::tri::others(tri, k);
        if x == b {
            o1 = y;
            n_ab += 1;
        } else if y == b {
            o2 = x;
            n_ab += 1;
        }
    }
    if n_ab == 0 {
        return Err(Reject::Link);
    }
    if on!(Locked) && n_ab > 2 {
        return Err(Reject::Locked);
    }

    // Boundary: a boundary vertex only slides along its own boundary edge, and a boundary
    // loop of three edges must not close up (or a lone triangle vanish).
    if fa & flag::BOUNDARY != 0 && on!(Boundary) {
        if n_ab != 1 {
            return Err(Reject::Boundary);
        }
        let (x1, x2) = mesh.boundary_ends(a);
        let (y1, y2) = mesh.boundary_ends(b);
        let x = if x1 == b { x2 } else { x1 };
        let y = if y1 == a { y2 } else { y1 };
        if x == y {
            return Err(Reject::Boundary);
        }
    }

    // Each surviving triangle: duplicate, own shape and turn, folds with its neighbours
    // after the collapse (the next survivor across a spoke and the unchanged triangles across
    // its outer edge; b's triangles across (b, o1) and (b, o2) once the link walk below has
    // found them). These rules go first because on flat, sliver-rich meshes (CAD) most
    // candidates fail them, and a refused candidate then skips the link walks (two thirds of
    // a check on fandisk). The verdict is the same in either order; only the reason a
    // refusal is counted under can differ.
    let pb = match at {
        Some(p) => p,
        None => mesh.p(b),
    };
    let mut first: Option<(usize, Shape)> = None;
    let mut prev: Option<(usize, Shape)> = None;
    // The survivors holding o1 or o2 and their shapes after the collapse, for the fold test
    // across (b, o1) and (b, o2). a's fan is a disk (an irregular fan is locked, and a legal
    // collapse keeps fans disks), so each of o1 and o2 is in at most one survivor: `more`
    // (a third) cannot happen, and is refused as locked rather than re-shaped (flash).
    let mut near: [Option<(usize, usize, Shape)>; 2] = [None, None];
    let mut more = false;
    for (t, k) in mesh.corners(a) {
        let old = mesh.tri(t);
        if old.contains(&b) {
            continue;
        }
        let (x, y) = crate::tri::others(old, k);
        if on!(Duplicate)
            && ((x == o1 && y == o2) || (x == o2 && y == o1))
            && mesh.corners(b).any(|(u, _)| {
                let s = mesh.tri(u);
                s.contains(&x) && s.contains(&y)
            })
        {
            return Err(Reject::Duplicate);
        }
        let now = survivor(mesh, rules, (t, k, old), pb, prev, &after)?;
        if x == o1 || y == o1 || x == o2 || y == o2 {
            match near.iter_mut().find(|s| s.is_none()) {
                Some(slot) => *slot = Some((x, y, now)),
                None => more = true,
            }
        }
        if first.is_none() {
            first = Some((x, now));
        }
        prev = Some((y, now));
    }
    // Link condition: the only common neighbours of a and b are o1 and o2. One walk of b's
    // list marks b's neighbours (as `Mesh::for_each_neighbour` names them: both of every
    // corner's, so a locked b's unordered list is covered too), so this is O(valence), and
    // finds b's triangles across (b, o1) and (b, o2), for the fold test. Around a locked b such
    // a triangle may be wound either way, and a second one (a non-manifold edge) is refused;
    // around a regular b neither happens.
    let (mut across_o1, mut across_o2, mut extra) = (NIL, NIL, false);
    let mut c = mesh.first(b);
    let mut guard = mesh.triangle_count();
    while c != NIL && guard > 0 {
        guard -= 1;
        let tri = mesh.tri(c >> 2);
        let (x, y) = crate::tri::others(tri, c & 3);
        mesh.mark(x, true);
        mesh.mark(y, true);
        if x != a && y != a {
            if x == o1 || y == o1 {
                extra |= across_o1 != NIL;
                across_o1 = c >> 2;
            }
            if x == o2 || y == o2 {
                extra |= across_o2 != NIL;
                across_o2 = c >> 2;
            }
        }
        c = mesh.after_in(c, b);
    }
    let mut common = false;
    mesh.for_each_neighbour(a, |x| {
        common |= x != b && x != o1 && x != o2 && mesh.has(x, flag::MARK);
    });
    mesh.for_each_neighbour(b, |x| mesh.mark(x, false));
    if on!(Link) && common {
        return Err(Reject::Link);
    }
    if on!(Locked) && extra {
        return Err(Reject::Locked);
    }

    // Folds across (b, o1) and (b, o2).
    if on!(Fold) {
        let across = |x: usize, y: usize, now: &Shape| {
            [(o1, across_o1), (o2, across_o2)]
                .iter()
                .any(|&(v, u)| (x == v || y == v) && u != NIL && folded(now, &after(u)))
        };
        for (x, y, now) in near.iter().flatten() {
            if across(*x, *y, now) {
                return Err(Reject::Fold);
            }
        }

        if more && on!(Locked) {
            // Unreachable while the locked rule is on (see `near`); refused, not guessed at.
            return Err(Reject::Locked);
        }
    }
    // The spoke between the last survivor and the first (a's list is a rotated cycle).
    if let (true, Some((fx, fs)), Some((ly, ls))) = (on!(Fold), first, prev) {
        if fx == ly && fx != o1 && fx != o2 && folded(&fs, &ls) {
            return Err(Reject::Fold);
        }
    }
    Ok(())
}

/// Welded seams: whether `a` may move onto `b` as far as its wedges go. Around `a`'s fan (in
/// fan order, a disc's last triangle next to its first) the wedge of `a` changes across some
/// spokes. One wedge: `a` is inside one attribute region, anything goes. Two (a seam through
/// `a`, or one that ends on `a`'s boundary): only along the seam, onto the vertex of a spoke
/// where the wedge changes (at a boundary that is never, since the boundary rule allows only
/// boundary edges: meshoptimizer locks a seam's end too). More (a corner where seams meet, or
/// a flat-shaded vertex, whose every face has its own wedge): never with
/// [`SeamCorners::Lock`](crate::seam::SeamCorners::Lock) (meshoptimizer's complex vertices);
/// with `Move` the wedges go with the removed triangles' neighbours (`Mesh::move_wedges`).
#[cfg(feature = "seams")]
#[inline(never)]
fn along_seam<L: Index, I: Index>(mesh: &Mesh<'_, L, I>, a: usize, b: usize) -> bool {
    let wedge = |t: usize, k: usize| {
        mesh.wedges
            .get(t)
            .and_then(|w| w.get(k))
            .map(|x| x.to_usize())
    };
    let (mut changes, mut onto_b) = (0, false);
    let mut first: Option<Option<usize>> = None;
    let mut prev: Option<(Option<usize>, usize)> = None;
    for (t, k) in mesh.corners(a) {
        let tri = mesh.tri(t);
        let w = wedge(t, k);
        // The spoke shared with the previous triangle is this one's `x` (its next vertex).
        if let Some((pw, _)) = prev {
            if pw != w {
                changes += 1;
                onto_b |= tri[next3(k)] == b;
            }
        }
        if first.is_none() {
            first = Some(w);
        }
        prev = Some((w, tri[prev3(k)]));
    }
    // A disc closes: its last triangle's `y` spoke is its first triangle's `x`.
    if let (false, Some(f), Some((lw, ly))) = (mesh.has(a, flag::BOUNDARY), first, prev) {
        if f != lw {
            changes += 1;
            onto_b |= ly == b;
        }
    }
    // A boundary fan's wedges are one more than its changes, a disc's as many.
    let wedges = changes + usize::from(mesh.has(a, flag::BOUNDARY));
    if wedges > 2 {
        return !mesh.lock_corners;
    }
    // Charts are kept only where the wedges carry attributes (`Lock`): with `Move` a split
    // index buffer's wedges carry nothing, and a mesh shaded flat (every face its own chart)
    // would not simplify at all.
    (wedges != 2 || onto_b) && (wedges < 2 || !mesh.lock_corners || !removes_a_chart(mesh, a, b))
}

/// Welded seams: whether a triangle the collapse `a -> b` removes is the last of its chart
/// (the triangles joined to it across edges where both ends keep their wedges): no
/// surviving triangle across any of its edges shares both wedges of that edge. Such a
/// triangle is the last piece of a texture chart or of a material (a material boundary is a
/// seam, `host-sim simplify` joins a mesh's primitives), and a collapse along a seam would
/// take it whole. Only a vertex with two or more wedges can remove one: inside a chart the
/// removed triangles have chart neighbours in `a`'s fan. Asked only with
/// [`SeamCorners::Lock`](crate::seam::SeamCorners::Lock), the wedges of real attributes.
#[cfg(feature = "seams")]
fn removes_a_chart<L: Index, I: Index>(mesh: &Mesh<'_, L, I>, a: usize, b: usize) -> bool {
    let wedge = |t: usize, v: usize| {
        let k = mesh.tri(t).iter().position(|&x| x == v)?;
        mesh.wedges.get(t)?.get(k).map(|x| x.to_usize())
    };
    mesh.corners(a).any(|(t, k)| {
        let tri = mesh.tri(t);
        let (x, y) = crate::tri::others(tri, k);
        let o = if x == b {
            y
        } else if y == b {
            x
        } else {
            return false;
        };
        // Edge a-b joins only the other removed triangle, which goes too.
        let joined = [(b, o), (a, o)].into_iter().any(|(u, v)| {
            mesh.corners(u).any(|(s, _)| {
                s != t
                    && mesh.tri(s).contains(&v)
                    && !mesh.tri(s).contains(&if u == a { b } else { a })
                    && wedge(s, u) == wedge(t, u)
                    && wedge(s, v) == wedge(t, v)
            })
        });
        !joined
    })
}

/// [`check`] for `b` moved to `at` (optimal placement), then the rules on `b`'s own
/// triangles there ([`check_moved_b`]). Separate from `check` so that the read-only modes'
/// images do not carry the moved-`b` rules.
pub(crate) fn check_placed<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    rules: &Rules,
    a: usize,
    b: usize,
    at: V3,
) -> Result<(), Reject> {
    check(mesh, rules, a, b, Some(at))?;
    check_moved_b(mesh, rules, a, b, at)
}

/// The shape, turn and fold rules on `b`'s surviving triangles with `b` at `p` (`a` merged
/// into it). A fold is looked for across each of their edges, against the triangle there after
/// the collapse, found as [`check`] finds a's: across a spoke `b-x` the survivor before in
/// `b`'s fan order (the list is a rotated cycle, so the last one is before the first), across
/// the outer edge `x-y` the triangle after in `y`'s. Across `b-o1` and `b-o2` the neighbours
/// are a's survivors, and [`check`] has tested those pairs already. Never inlined: only optimal
/// placement needs it, and inlined its locals would deepen [`check`]'s frame for every mode
/// (the micro:bit has 4.5 KB of stack).
#[inline(never)]
fn check_moved_b<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    rules: &Rules,
    a: usize,
    b: usize,
    p: V3,
) -> Result<(), Reject> {
    let after = |u: usize| shape_moved(mesh, u, a, b, p);
    let mut first: Option<(usize, Shape)> = None;
    let mut prev: Option<(usize, Shape)> = None;
    for (t, k) in mesh.corners(b) {
        let old = mesh.tri(t);
        if old.contains(&a) {
            continue;
        }
        let (x, y) = crate::tri::others(old, k);
        let now = survivor(mesh, rules, (t, k, old), p, prev, &after)?;
        if first.is_none() {
            first = Some((x, now));
        }
        prev = Some((y, now));
    }
    if let (true, Some((fx, fs)), Some((ly, ls))) = (on!(Fold), first, prev) {
        if fx == ly && folded(&fs, &ls) {
            return Err(Reject::Fold);
        }
    }
    Ok(())
}

/// The live triangle other than `skip`'s holding both `x` and `y`, if any (`x`'s list).
fn other_with<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    x: usize,
    y: usize,
    skip: usize,
) -> Option<usize> {
    mesh.corners(x).map(|(t, _)| t).find(|&t| {
        let s = mesh.tri(t);
        s.contains(&y) && !s.contains(&skip)
    })
}

/// The rules on a vertex removal: `v`'s fan replaced by `new`, triangles over its `ring`
/// (ring positions, each wound in ring order; a `boundary` ring's closing edge, last to first,
/// becomes a boundary edge), each checked against its plane's unit normal in `planes` (the
/// average plane, or its side's of a feature line). The hard rules of a collapse, for
/// triangles that have no "before":
///
/// * `locked`: a ring vertex is locked (its list has no fan order to splice into);
/// * `link`: a diagonal, or a boundary ring's closing edge, is already an edge (a
///   non-manifold edge, or a boundary loop closed);
/// * `duplicate`: a new triangle already exists;
/// * `sliver`: a new triangle has no area, or one so thin that rounding decides its normal;
/// * `fold`: a new triangle faces away from the average plane, or folds against the triangle
///   across its loop edge or another new one across a diagonal;
/// * `normal_turn`: a new triangle's normal is farther from the average plane's than
///   [`Config::max_normal_turn_deg`].
pub(crate) fn check_fan<L: Index, I: Index>(
    mesh: &Mesh<'_, L, I>,
    rules: &Rules,
    v: usize,
    (ring, boundary): (&[usize], bool),
    new: &[[u8; 3]],
    planes: &[V3],
) -> Result<(), Reject> {
    let n = ring.len();
    let at = |k: u8| ring.get(k as usize).copied().unwrap_or(NIL);
    if on!(Locked) && ring.iter().any(|&x| mesh.has(x, flag::LOCKED)) {
        return Err(Reject::Locked);
    }
    for (i, (&t, &normal)) in new.iter().zip(planes).enumerate() {
        let tri = t.map(at);
        let now = Shape::of(tri.map(|x| mesh.p(x)));
        if on!(Sliver) && now.quality < FLAT {
            return Err(Reject::Sliver);
        }
        let d = math::dot(now.n, normal);
        if on!(Fold) && d <= 0.0 {
            return Err(Reject::Fold);
        }
        // Farther from the plane's normal than the turn limit (as `shape_rules` compares).
        let turned = if rules.cos_turn >= 0.0 {
            d < 0.0 || d * d < rules.cos_turn2 * now.n2
        } else {
            d < 0.0 && d * d > rules.cos_turn2 * now.n2
        };
        if on!(NormalTurn) && turned {
            return Err(Reject::NormalTurn);
        }
        if on!(Duplicate) {
            let [x, y, z] = tri;
            if mesh
                .corners(x)
                .any(|(u, _)| mesh.tri(u).contains(&y) && mesh.tri(u).contains(&z))
            {
                return Err(Reject::Duplicate);
            }
        }
        for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[0], t[2])] {
            let (x, y) = (at(p), at(q));
            // Loop edges (ring neighbours; around an interior vertex also last-first) stay.
            let loop_edge = q == p + 1 || (!boundary && p == 0 && q as usize + 1 == n);
            if loop_edge {
                if on!(Fold) {
                    if let Some(u) = other_with(mesh, x, y, v) {
                        if folded(&now, &shape_of(mesh, u)) {
                            return Err(Reject::Fold);
                        }
                    }
                }
            } else {
                if on!(Link) && other_with(mesh, x, y, v).is_some() {
                    return Err(Reject::Link);
                }
                // The other new triangle on this diagonal (none on a boundary's closing edge).
                if on!(Fold) {
                    for &o in new.iter().skip(i + 1) {
                        if o.contains(&p) && o.contains(&q) {
                            let other = Shape::of(o.map(|k| mesh.p(at(k))));
                            if folded(&now, &other) {
                                return Err(Reject::Fold);
                            }
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{is_dead, Positions};

    /// A pair whose normals meet at the checker's limit (dot −0.9 in `f64`) or a little inside
    /// it is folded here: the margin that covers `f32` rounding.
    #[test]
    fn a_pair_at_the_checkers_fold_limit_is_folded() {
        let shape = |n: V3| Shape {
            n,
            n2: math::dot(n, n),
            quality: 0.05,
        };
        let up = shape([0.0, 0.0, 1.0]);
        let at = |d: f32| shape([math::sqrt(1.0 - d * d), 0.0, d]);
        assert!(folded(&up, &at(-0.9)));
        assert!(folded(&up, &at(-0.895)));
        assert!(!folded(&up, &at(-0.88)));
    }

    const N: usize = 7;
    const NV: usize = (N + 1) * (N + 1);
    const NT: usize = 2 * N * N;

    /// An accordion-folded open grid, `N` x `N` quads: interior vertices of valence 6 whose
    /// corner lists start at their lowest-numbered triangle, so that most of `b`'s lists start
    /// inside the fan (a first and a last survivor that share a spoke).
    fn grid() -> ([[f32; 3]; NV], [[u16; 3]; NT]) {
        let mut p = [[0.0f32; 3]; NV];
        for (i, q) in p.iter_mut().enumerate() {
            let (x, y) = ((i % (N + 1)) as f32, (i / (N + 1)) as f32);
            let h = (i as u32).wrapping_mul(2_654_435_761) >> 16;
            *q = [
                x,
                y,
                // Ridges along y (an accordion: steep dihedrals, so that a moved triangle can
                // fold against one neighbour and not the others) and a bump per vertex.
                if i % 2 == 0 { 0.9 } else { -0.9 } + 0.35 * (h as f32 / 65_536.0 - 0.5),
            ];
        }
        let mut t = [[0u16; 3]; NT];
        for y in 0..N {
            for x in 0..N {
                let a = (y * (N + 1) + x) as u16;
                let (b, c, d) = (a + 1, a + N as u16 + 1, a + N as u16 + 2);
                t[2 * (y * N + x)] = [a, b, d];
                t[2 * (y * N + x) + 1] = [a, d, c];
            }
        }
        (p, t)
    }

    /// A vertex removal whose diagonal is already an edge is refused by the link rule: a
    /// pentagon fan around vertex 0 (ring 1..=5) with a vertex 6 below ring vertices 1, 2 and
    /// 3, whose triangle (1, 3, 6) holds edge 1-3. Triangulating the hole with the diagonal
    /// 1-3 would put a third triangle on it; the diagonals 1-4 and 4-2 put none. Fails if the
    /// diagonal-exists check is switched off (`TINYDECIMATE_RULE_OFF=link`).
    #[test]
    fn removal_refuses_a_diagonal_that_is_an_edge() -> Result<(), crate::Error> {
        let mut p = [[0.0f32; 3]; 7];
        p[0] = [0.0, 0.0, 0.2];
        for i in 0..5 {
            let a = i as f32 * core::f32::consts::TAU / 5.0;
            p[i + 1] = [
                math::cos_deg(a.to_degrees()),
                math::cos_deg(90.0 - a.to_degrees()),
                0.0,
            ];
        }
        p[6] = [
            (p[1][0] + p[2][0] + p[3][0]) / 3.0,
            (p[1][1] + p[2][1] + p[3][1]) / 3.0,
            -0.8,
        ];
        let mut t: [[u16; 3]; 8] = [
            [0, 1, 2],
            [0, 2, 3],
            [0, 3, 4],
            [0, 4, 5],
            [0, 5, 1],
            [2, 1, 6],
            [3, 2, 6],
            [1, 3, 6],
        ];
        let (mut head, mut next, mut flags) = ([0u16; 7], [[0u16; 3]; 8], [0u8; 7]);
        let (mut s0, mut s1) = ([0u16; 7], [0u16; 7]);
        let mesh = Mesh::build(
            Positions::Read(&p),
            &mut t,
            &mut head,
            &mut next,
            &mut flags,
            (&mut s0, &mut s1),
        )?;
        let rules = Rules::new(&Config::new());
        let ring = [1, 2, 3, 4, 5];
        let up = [[0.0, 0.0, 1.0]; 3];
        assert!((1..6).all(|v| !mesh.has(v, flag::LOCKED)));
        // Ring positions: the diagonal 0-2 is vertices 1-3.
        let through_edge = [[0u8, 1, 2], [0, 2, 3], [0, 3, 4]];
        assert_eq!(
            check_fan(&mesh, &rules, 0, (&ring, false), &through_edge, &up),
            Err(Reject::Link)
        );
        let around_it = [[0u8, 1, 3], [1, 2, 3], [0, 3, 4]];
        assert_eq!(
            check_fan(&mesh, &rules, 0, (&ring, false), &around_it, &up),
            Ok(())
        );
        Ok(())
    }

    /// Whether one of `b`'s survivors of `a -> b` with `b` at `p` folds against any other
    /// triangle that shares an edge with it after the collapse: a search of every triangle,
    /// what [`check_moved_b`]'s fan-order lookups (and [`check`]'s across `b-o1`, `b-o2`)
    /// stand for.
    fn folds_by_search(mesh: &Mesh<'_, u16, u16>, a: usize, b: usize, p: V3) -> bool {
        let merged = |v: usize| if v == a { b } else { v };
        let survives = |t: usize| {
            let s = mesh.tri(t);
            let removed = s.contains(&a) && s.contains(&b);
            !is_dead(s) && !removed
        };
        for t in 0..mesh.triangle_count() {
            let old = mesh.tri(t);
            if !survives(t) || !old.contains(&b) || old.contains(&a) {
                continue;
            }
            let now = shape_moved(mesh, t, a, b, p);
            for (u, w) in [(old[0], old[1]), (old[1], old[2]), (old[2], old[0])] {
                for s in 0..mesh.triangle_count() {
                    let m = mesh.tri(s).map(merged);
                    if s != t
                        && survives(s)
                        && m.contains(&u)
                        && m.contains(&w)
                        && folded(&now, &shape_moved(mesh, s, a, b, p))
                    {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// The shape and turn rules alone on `b`'s survivors.
    fn shapes_allow(mesh: &Mesh<'_, u16, u16>, rules: &Rules, a: usize, b: usize, p: V3) -> bool {
        mesh.corners(b).all(|(t, _)| {
            let old = mesh.tri(t);
            old.contains(&a)
                || shape_rules(
                    rules,
                    &Shape::of(old.map(|v| mesh.p(v))),
                    &shape_moved(mesh, t, a, b, p),
                )
                .is_ok()
        })
    }

    /// Optimal placement: on every edge of the grid, in both directions, with the kept vertex
    /// moved to 52 positions around it (26 directions, two distances), under the shipped limits and under limits loose enough
    /// for many folds, [`check_placed`] says yes exactly when [`check`] does and `b`'s moved
    /// triangles keep their shapes and fold against no neighbour found by a search of every
    /// triangle. Fails when any of `check_moved_b`'s three fold lookups (spoke, outer edge,
    /// first and last survivor) is left out.
    #[test]
    fn moved_b_rules_agree_with_a_search() -> Result<(), crate::Error> {
        let (p, mut t) = grid();
        let (mut head, mut next, mut flags) = ([0u16; NV], [[0u16; 3]; NT], [0u8; NV]);
        let (mut s0, mut s1) = ([0u16; NV], [0u16; NV]);
        let mesh = Mesh::build(
            Positions::Read(&p),
            &mut t,
            &mut head,
            &mut next,
            &mut flags,
            (&mut s0, &mut s1),
        )?;
        // The shipped limits, and limits so loose that the fold rule has the last word.
        let mut loose = Config::stored();
        loose.max_normal_turn_deg = 179.0;
        loose.min_quality = 0.0;
        let (mut cases, mut folds) = (0, 0);
        for rules in [Rules::new(&Config::stored()), Rules::new(&loose)] {
            for a in 0..NV {
                for (t0, k) in mesh.corners(a) {
                    let b = mesh.tri(t0)[next3(k)];
                    let (pb, l) = (mesh.p(b), math::sub(mesh.p(a), mesh.p(b)));
                    let l2 = math::dot(l, l);
                    let l = l2 * math::rsqrt(l2);
                    for i in 0..54 {
                        if i % 27 == 13 {
                            continue;
                        }
                        let d = [
                            (i % 3) as f32 - 1.0,
                            ((i / 3) % 3) as f32 - 1.0,
                            ((i / 9) % 3) as f32 - 1.0,
                        ];
                        let r = if i < 27 { 0.6 } else { 1.5 };
                        let at = math::add(pb, math::scale(d, r * l));
                        if check(&mesh, &rules, a, b, Some(at)).is_err() {
                            continue;
                        }
                        cases += 1;
                        let fold = folds_by_search(&mesh, a, b, at);
                        folds += usize::from(fold);
                        let expected = shapes_allow(&mesh, &rules, a, b, at) && !fold;
                        assert_eq!(
                            check_placed(&mesh, &rules, a, b, at).is_ok(),
                            expected,
                            "{a} -> {b} at {at:?}"
                        );
                    }
                }
            }
        }
        assert!(
            cases > 1000 && folds > 100,
            "{cases} cases, {folds} with a fold"
        );
        Ok(())
    }
}

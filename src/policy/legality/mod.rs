//! Which collapses keep the mesh valid: the legality rules, declared once, in [`RULES`].
//!
//! A half-edge collapse `a -> b` (a moves onto b, b stays where it is, or moves to the cost's
//! placement) is refused when any rule fails. Each rule is one row of [`RULES`]: the
//! [`Reject`] it is counted under, its name (the report's label and its build-time switch),
//! what it protects, its [`Purpose`] and its source. The report's counts
//! ([`Rejections`](crate::Rejections)), the host tools' reports, the QEMU result files, the
//! golden files, `tests/rules.rs` and `scripts/rules-off.sh` all read this table; none of them
//! lists the rules again.
//!
//! # Purposes
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
//! candidates fail a shape rule, so they never pay for the walks. A
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
//! `tinydecimate simplify` and `bench`, the QEMU result file (room for 16 rules,
//! `meshfmt::REJECTION_SLOTS`), the golden files' text and `scripts/rules-off.sh`. What else
//! changes, only when it applies: a rule with a limit needs its [`Config`] field, checked in
//! `Config::validate` under a new `ConfigField`, and a field of the QEMU case file if golden
//! cases set it; a rule on vertex flags (like `locked` and `feature`) also belongs in the
//! queue's filters in `collapse` (`skip`, `rekey`), which keep such vertices out of the queue;
//! and the golden files' `.txt` show one more count, so they are re-blessed once
//! (`host-sim golden --bless`; the `.bin` outputs change only if the rule refuses something).

mod collapse;
mod fan;
#[cfg(feature = "seams")]
mod seam;
mod shape;
#[cfg(test)]
mod tests;

pub(crate) use collapse::{check, check_placed};
pub(crate) use fan::check_fan;
pub(crate) use shape::Shape;

use crate::math;
use crate::mesh::flag;
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
pub enum Purpose {
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
    pub purpose: Purpose,
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
        purpose: Purpose::Validity,
        source: "Cheng, Pan and Shi §3.1 (irregular vertices)",
    },
    Rule {
        reject: Reject::Feature,
        name: "feature",
        protects: "a is a feature vertex, or b is one and feature targets are not allowed: \
                   features survive",
        purpose: Purpose::Quality,
        source: "Lin Mouguang 2007 §3.3",
    },
    Rule {
        reject: Reject::Boundary,
        name: "boundary",
        protects: "a is on the boundary and a-b is not a boundary edge, or the boundary loop \
                   through a-b has only three edges: boundaries only shrink along themselves",
        purpose: Purpose::Validity,
        source: "Cheng, Pan and Shi §3.2(1), second and third conditions",
    },
    Rule {
        reject: Reject::Link,
        name: "link",
        protects: "a vertex adjacent to both a and b is not opposite a-b: the surface would \
                   pinch or gain a non-manifold edge",
        purpose: Purpose::Validity,
        source: "Cheng, Pan and Shi §3.2(1), first condition (the link condition)",
    },
    Rule {
        reject: Reject::Duplicate,
        name: "duplicate",
        protects: "a triangle of a would become a copy of one of b's",
        purpose: Purpose::Validity,
        source: "",
    },
    Rule {
        reject: Reject::NormalTurn,
        name: "normal_turn",
        protects: "a surviving triangle's normal turns by more than \
                   Config::max_normal_turn_deg",
        purpose: Purpose::Quality,
        source: "Cheng, Pan and Shi §3.2(2), the dihedral threshold",
    },
    Rule {
        reject: Reject::Sliver,
        name: "sliver",
        protects: "a surviving triangle gets zero area or a normal that rounding decides \
                   (validity), or leaves its plane with a quality below Config::min_quality \
                   that is also worse than before (preference)",
        purpose: Purpose::ValidityAndQuality,
        source: "",
    },
    Rule {
        reject: Reject::Fold,
        name: "fold",
        protects: "a surviving triangle and a neighbour across any of its edges end up with \
                   nearly opposite normals (more than about 154° apart)",
        purpose: Purpose::Validity,
        source: "Cheng, Pan and Shi §3.2(2)",
    },
    Rule {
        reject: Reject::Bound,
        name: "bound",
        protects: "a control point would end farther than Config::max_error from every \
                   triangle of the new fan (bounded entry points only)",
        purpose: Purpose::Guarantee,
        source: "Zhu, Wang and Meng 2007 §3",
    },
    Rule {
        reject: Reject::Seam,
        name: "seam",
        protects: "with welded seams (crate::seam): a on a seam (its wedge changes across one \
                   or two spokes) moves only along that seam, so the seam keeps its shape and \
                   no triangle takes corners from both sides, and never takes a chart's (a \
                   material's) last triangle (welded runs only)",
        purpose: Purpose::Quality,
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

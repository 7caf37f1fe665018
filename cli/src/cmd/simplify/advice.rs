//! What `simplify` says when it stops short of its target: the limit that stopped it, the
//! option that relaxes it, and the fallback that always reaches a count.
//!
//! The limit is read from the report: its stop, then, for [`Stop::NoLegalCollapse`], the rule
//! of `legality::RULES` that refused the most candidates. The feature and locked vertices
//! never enter the queue, so their refusals are not counted; when no rule refused anything the
//! report's feature, then locked, vertex counts name the limit. [`RELIEF`] says, per rule,
//! which option relaxes it; validity rules have none. The fallback is vertex clustering,
//! `tinydecimate cluster`, whose `--target-triangles N` picks the finest grid with at most N
//! triangles, so it reaches any count; `--then-collapse N` from a larger clustering target
//! finishes with collapses, at a lower error.

use tinydecimate::{Reject, Report, Stop};

/// One row of [`RELIEF`]: a legality rule and what relaxes it.
#[derive(Clone, Copy, Debug)]
pub struct Relief {
    /// The rule.
    pub rule: Reject,
    /// The `simplify` option that relaxes it, with an example value; `None` for a validity
    /// rule (the output would stop being a valid mesh of the same topology).
    pub option: Option<(&'static str, &'static str)>,
    /// What its refusals mean.
    pub why: &'static str,
}

const fn row(
    rule: Reject,
    option: Option<(&'static str, &'static str)>,
    why: &'static str,
) -> Relief {
    Relief { rule, option, why }
}

/// Per legality rule, in the order of `RULES`: the option that relaxes it.
pub const RELIEF: &[Relief] = &[
    row(
        Reject::Locked,
        None,
        "vertices on non-manifold, pinched or inconsistently wound edges stay as they are \
         (tinydecimate check lists the input's defects)",
    ),
    row(
        Reject::Feature,
        Some(("--no-features", "--no-features")),
        "feature vertices are kept (a larger --lambda marks fewer)",
    ),
    row(
        Reject::Boundary,
        None,
        "boundaries only shrink along themselves",
    ),
    row(Reject::Link, None, "the collapse would pinch the surface"),
    row(
        Reject::Duplicate,
        None,
        "the collapse would make a triangle twice",
    ),
    row(
        Reject::NormalTurn,
        Some(("--max-turn", "--max-turn 120")),
        "a triangle would turn further than --max-turn degrees (60 by default) in one collapse",
    ),
    row(
        Reject::Sliver,
        Some(("--min-quality", "--min-quality 0")),
        "a collapse would make a triangle thinner than --min-quality (0.05 by default)",
    ),
    row(
        Reject::Fold,
        None,
        "two triangles would fold onto each other",
    ),
    row(
        Reject::Bound,
        Some(("--max-error", "a larger --max-error")),
        "a control point would leave the error bound",
    ),
    row(
        Reject::Seam,
        Some(("--seams", "--seams split")),
        "seam vertices move only along their seam (split, each seam is an open boundary)",
    ),
];

/// What a run did, as far as the advice needs it (a [`Report`]'s fields).
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// Why it stopped.
    pub stop: Stop,
    /// Whether it reached its target.
    pub target_reached: bool,
    /// The target triangle count.
    pub target_triangles: usize,
    /// Triangles out.
    pub triangles_out: usize,
    /// Refusals per rule, in the order of `RULES`.
    pub refused: Vec<u32>,
    /// Feature vertices (never in the queue).
    pub feature_vertices: usize,
    /// Locked vertices (never in the queue).
    pub locked_vertices: usize,
    /// The normal-turn limit in use, degrees (`Config::max_normal_turn_deg`).
    pub max_turn: f32,
    /// The quality limit in use (`Config::min_quality`).
    pub min_quality: f32,
}

impl Outcome {
    /// The limits `config` ran with (`From<&Report>` assumes `Config::new()`'s): the advice
    /// names only values that relax them further.
    pub fn in_use(mut self, config: &tinydecimate::Config) -> Outcome {
        self.max_turn = config.max_normal_turn_deg();
        self.min_quality = config.min_quality();
        self
    }
}

impl From<&Report> for Outcome {
    fn from(r: &Report) -> Outcome {
        Outcome {
            stop: r.stop,
            target_reached: r.target_reached,
            target_triangles: r.target_triangles,
            triangles_out: r.triangles_out,
            refused: r.rejected.iter().map(|(_, n)| n).collect(),
            feature_vertices: r.feature_vertices,
            locked_vertices: r.locked_vertices,
            max_turn: tinydecimate::Config::new().max_normal_turn_deg(),
            min_quality: tinydecimate::Config::new().min_quality(),
        }
    }
}

/// A limit an option relaxes, with how much it refused.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Relax {
    /// The rule's name (or the stop's).
    pub limit: &'static str,
    /// Its refusals (`unit` "refusals") or, for feature and locked vertices, which never enter
    /// the queue, the vertices so flagged ("vertices").
    pub count: usize,
    /// What `count` counts.
    pub unit: &'static str,
    /// The option.
    pub option: &'static str,
    /// The option with an example value.
    pub example: &'static str,
}

/// Why a run stopped short and what to do.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Advice {
    /// The stop, as the report says it.
    pub stop: String,
    /// The limit that stopped it: the rule that refused the most, or `max_passes`,
    /// `max_cost`, `log_full` (the stop itself), or `none`.
    pub limit: &'static str,
    /// Its refusals, or vertices (see [`Relax::count`]).
    pub count: usize,
    /// What `count` counts.
    pub unit: &'static str,
    /// What the limit means.
    pub why: &'static str,
    /// What to relax, first the suggestion: the limit itself when an option relaxes it, then
    /// the other rules that refused and that an option relaxes, most first, and the feature
    /// vertices when there are any. Empty when nothing can be relaxed.
    pub relax: Vec<Relax>,
    /// The `tinydecimate cluster` command that reaches the target: vertex clustering alone
    /// (`None`: not given, see `textured.rs`).
    pub fallback: Option<String>,
    /// The same, clustering to twice the target and collapsing the rest: lower error.
    pub fallback_then_collapse: Option<String>,
}

/// The advice for a run that stopped short of its target (`None` when it reached it).
/// `input`, `output`: the file names the fallback commands are written with.
pub fn advise(o: &Outcome, input: &str, output: &str) -> Option<Advice> {
    if o.target_reached || o.stop == Stop::Target {
        return None;
    }
    let refusals: u32 = o.refused.iter().sum();
    // Each rule's count, most first (a stable sort: ties in table order). Feature and locked
    // vertices never enter the queue: their vertex counts stand in for refusals only when no
    // rule refused anything (feature vertices are still offered below).
    let mut counted: Vec<(&Relief, usize, &'static str)> = RELIEF
        .iter()
        .map(|r| match r.rule {
            Reject::Feature if refusals == 0 => (r, o.feature_vertices, "vertices"),
            Reject::Locked if refusals == 0 => (r, o.locked_vertices, "vertices"),
            _ => {
                let n = o.refused.get(r.rule as usize).copied().unwrap_or(0);
                (r, n as usize, "refusals")
            }
        })
        .collect();
    counted.sort_by_key(|c| std::cmp::Reverse(c.1));
    // An example must relax the limit in use: a larger turn than the one given (179 is the
    // largest accepted), a quality of 0 unless it is 0 already; else the rule is not offered.
    let example = |rule: Reject, example: &'static str| match rule {
        Reject::NormalTurn if o.max_turn >= 179.0 => None,
        Reject::NormalTurn if o.max_turn >= 120.0 => Some("--max-turn 179"),
        Reject::Sliver if o.min_quality <= 0.0 => None,
        _ => Some(example),
    };
    let relaxable = |(r, n, unit): &(&Relief, usize, &'static str)| {
        let (option, given) = r.option.filter(|_| *n > 0)?;
        example(r.rule, given).map(|example| Relax {
            limit: r.rule.name(),
            count: *n,
            unit,
            option,
            example,
        })
    };
    let mut relax: Vec<Relax> = counted.iter().filter_map(relaxable).collect();
    if let Some(feature) = RELIEF.iter().find(|r| r.rule == Reject::Feature) {
        if refusals > 0 {
            relax.extend(relaxable(&(feature, o.feature_vertices, "vertices")));
        }
    }
    let (limit, count, unit, why) = match o.stop {
        Stop::MaxPasses => {
            relax = vec![Relax {
                limit: "max_passes",
                count: 0,
                unit: "passes",
                option: "--schedule",
                example: "--schedule greedy",
            }];
            (
                "max_passes",
                0,
                "",
                "the passes schedule ran all its passes",
            )
        }
        Stop::MaxCost => {
            relax.clear();
            let why = "every collapse left costs more than Config::max_cost";
            ("max_cost", 0, "", why)
        }
        Stop::LogFull => {
            relax.clear();
            ("log_full", 0, "", "the collapse log is full")
        }
        Stop::ErrorLimit => {
            // On purpose: what is left would cut corners. Raising the limit is the one lever,
            // and only a value above the one in use changes anything: the report does not say
            // what the next collapse would need, so the advice names the value that always
            // goes further, `none`.
            relax = vec![Relax {
                limit: "error_limit",
                count: 0,
                unit: "",
                option: "--error-limit",
                example: "--error-limit none (or any value above the one in use)",
            }];
            let why = "every collapse left is over the error limit in use: reaching the count \
                       would cut corners";
            ("error_limit", 0, "", why)
        }
        _ => match counted.first() {
            Some((r, n, unit)) if *n > 0 => (r.rule.name(), *n, *unit, r.why),
            _ => ("none", 0, "", "no collapse was refused"),
        },
    };
    // A target of 0 triangles is the empty mesh: no command is worth advising to reach it.
    let (fallback, fallback_then_collapse) = match fallbacks(input, output, o.target_triangles) {
        Some((a, b)) => (Some(a), Some(b)),
        None => (None, None),
    };
    Some(Advice {
        stop: format!("{:?}", o.stop),
        limit,
        count,
        unit,
        why,
        relax,
        fallback,
        fallback_then_collapse,
    })
}

/// The target line of a run to an error bound alone (`--max-error` without a count): the error
/// it ran to, `bound` as given (`0.5%` of the diagonal, or a distance) and `d_hold` in the
/// input's units, and whether it was reached: yes when the bound is what stopped the run
/// (every collapse left would break it), else no, with the limit that stopped it first and
/// the option that relaxes it, read as [`advise`] reads a shortfall.
pub fn bound_target(bound: &str, d_hold: f32, report: &Report) -> String {
    let of = if bound.ends_with('%') {
        " of the diagonal"
    } else {
        ""
    };
    let head = format!("error ≤ {bound}{of} = {d_hold:.6e}");
    let o = Outcome {
        target_reached: false,
        ..Outcome::from(report)
    };
    let advice = match o.stop {
        Stop::Target | Stop::Running => None,
        _ => advise(&o, "", ""),
    };
    match advice {
        Some(a) if a.limit != "bound" => {
            let relax = a
                .relax
                .first()
                .map_or(String::new(), |r| format!(": relax {}", r.example));
            format!("{head} (reached: no, {} stopped it first{relax})", a.limit)
        }
        _ => format!("{head} (reached: yes, as far as the bound allows)"),
    }
}

/// The two `tinydecimate cluster` commands that reach `n` triangles: clustering alone, and
/// clustering to at most `2n` then collapsing (`cluster --then-collapse` reaches its count:
/// when the collapses stop short it clusters again, closer to the count, and collapses once
/// more). `None` for `n` = 0, which only the empty mesh reaches.
pub fn fallbacks(input: &str, output: &str, n: usize) -> Option<(String, String)> {
    if n == 0 {
        return None;
    }
    let cluster = format!("tinydecimate cluster {input} {output} --target-triangles");
    Some((
        format!("{cluster} {n}"),
        format!("{cluster} {} --then-collapse {n}", 2 * n),
    ))
}

impl Advice {
    /// The advice as lines of `simplify`'s text report, `indent` before each.
    pub fn text(&self, o: &Outcome, indent: &str) -> String {
        let relaxes_limit = self.relax.first().is_some_and(|r| r.limit == self.limit);
        let relax: Vec<String> = self
            .relax
            .iter()
            .map(|r| {
                if r.count > 0 {
                    format!("{} ({}: {} {})", r.example, r.limit, r.count, r.unit)
                } else {
                    r.example.to_string()
                }
            })
            .collect();
        let mut s = format!(
            "{indent}stopped short          {} triangles for a target of {} ({})\n\
             {indent}limit                  {}{}: {}{}\n\
             {indent}relax                  {}\n",
            o.triangles_out,
            o.target_triangles,
            self.stop,
            self.limit,
            if self.count > 0 {
                format!(", {} {}", self.count, self.unit)
            } else {
                String::new()
            },
            self.why,
            if relaxes_limit || self.relax.is_empty() && self.limit == "none" {
                ""
            } else {
                " (no option relaxes it)"
            },
            if relax.is_empty() {
                "nothing refused can be relaxed".to_string()
            } else {
                relax.join("; then ")
            },
        );
        if let (Some(a), Some(b)) = (&self.fallback, &self.fallback_then_collapse) {
            s += &format!(
                "{indent}fallback               {a} (vertex clustering: reaches the count)\n\
                 {indent}                       {b} (clusters to at most twice the count, \
                 then collapses: lower error)\n"
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tinydecimate::legality::Purpose;
    use tinydecimate::{Config, RULES};

    /// An outcome that stopped short with these refusals (by rule name).
    fn short(stop: Stop, refused: &[(&str, u32)], features: usize, locked: usize) -> Outcome {
        Outcome {
            stop,
            target_reached: false,
            target_triangles: 100,
            triangles_out: 120,
            refused: RULES
                .iter()
                .map(|r| refused.iter().find(|x| x.0 == r.name).map_or(0, |x| x.1))
                .collect(),
            feature_vertices: features,
            locked_vertices: locked,
            max_turn: 60.0,
            min_quality: 0.05,
        }
    }

    fn options(a: &Advice) -> Vec<&str> {
        a.relax.iter().map(|r| r.option).collect()
    }

    #[test]
    fn one_row_per_rule_and_no_option_for_validity_rules() {
        assert_eq!(RELIEF.len(), RULES.len());
        for (row, rule) in RELIEF.iter().zip(RULES) {
            assert_eq!(row.rule, rule.reject, "{}", rule.name);
            assert_eq!(
                row.option.is_none(),
                rule.purpose == Purpose::Validity,
                "{}",
                rule.name
            );
            if let Some((option, example)) = row.option {
                assert!(example.contains(option), "{example}");
            }
        }
    }

    #[test]
    fn the_rule_that_refused_most_is_named_with_its_option() {
        // pr2_sensor_mount at 10 %.
        let o = short(
            Stop::NoLegalCollapse,
            &[
                ("boundary", 2835),
                ("link", 691),
                ("normal_turn", 12942),
                ("sliver", 3427),
                ("fold", 1117),
            ],
            122,
            66,
        );
        let a = advise(&o, "in.obj", "out.obj").expect("stopped short");
        assert_eq!(
            (a.limit, a.count, a.unit),
            ("normal_turn", 12942, "refusals")
        );
        assert_eq!(
            options(&a),
            ["--max-turn", "--min-quality", "--no-features"]
        );
        assert_eq!(a.relax[2].unit, "vertices");
        assert_eq!(
            a.fallback.as_deref(),
            Some("tinydecimate cluster in.obj out.obj --target-triangles 100")
        );
        assert_eq!(
            a.fallback_then_collapse.as_deref(),
            Some("tinydecimate cluster in.obj out.obj --target-triangles 200 --then-collapse 100")
        );
        let text = a.text(&o, "  ");
        assert!(text.contains("limit                  normal_turn, 12942 refusals"));
        assert!(text.contains("relax                  --max-turn 120 (normal_turn"));
        assert!(!text.contains("no option relaxes it"));
        assert!(text.contains("--then-collapse 100"));
    }

    #[test]
    fn a_validity_limit_says_so_and_offers_what_can_be_relaxed() {
        let o = short(
            Stop::NoLegalCollapse,
            &[("fold", 1382), ("normal_turn", 623), ("sliver", 161)],
            0,
            0,
        );
        let a = advise(&o, "a", "b").unwrap();
        assert_eq!(a.limit, "fold");
        assert_eq!(options(&a), ["--max-turn", "--min-quality"]);
        assert!(a.text(&o, "").contains("(no option relaxes it)"));
        // Nothing relaxable refused: nothing offered but the fallback.
        let o = short(
            Stop::NoLegalCollapse,
            &[("boundary", 10), ("link", 3)],
            0,
            4,
        );
        let a = advise(&o, "a", "b").unwrap();
        assert_eq!(a.limit, "boundary");
        assert!(a.relax.is_empty());
        let text = a.text(&o, "");
        assert!(text.contains("nothing refused can be relaxed") && text.contains("fallback"));
    }

    #[test]
    fn flagged_vertices_name_the_limit_when_nothing_was_refused() {
        let o = short(Stop::NoLegalCollapse, &[], 40, 7);
        let a = advise(&o, "a", "b").unwrap();
        assert_eq!((a.limit, a.count, a.unit), ("feature", 40, "vertices"));
        assert_eq!(options(&a), ["--no-features"]);
        let o = short(Stop::NoLegalCollapse, &[], 0, 7);
        let a = advise(&o, "a", "b").unwrap();
        assert_eq!((a.limit, a.count), ("locked", 7));
        assert!(a.relax.is_empty());
    }

    #[test]
    fn stops_and_bounds() {
        let a = advise(&short(Stop::ErrorLimit, &[("sliver", 5)], 0, 0), "a", "b").unwrap();
        assert_eq!(a.limit, "error_limit");
        assert_eq!(a.relax.len(), 1);
        assert_eq!(a.relax[0].option, "--error-limit");
        // The value in use is not known here; `none` is the one that always goes further.
        assert!(
            a.relax[0].example.starts_with("--error-limit none"),
            "{:?}",
            a.relax
        );
        let a = advise(&short(Stop::MaxPasses, &[("sliver", 5)], 0, 0), "a", "b").unwrap();
        assert_eq!((a.limit, options(&a)), ("max_passes", vec!["--schedule"]));
        let a = advise(&short(Stop::MaxCost, &[("sliver", 5)], 0, 0), "a", "b").unwrap();
        assert_eq!(a.limit, "max_cost");
        assert!(a.relax.is_empty());
        let o = short(Stop::NoLegalCollapse, &[("bound", 900), ("seam", 20)], 0, 0);
        let a = advise(&o, "a", "b").unwrap();
        assert_eq!(
            (a.limit, options(&a)),
            ("bound", vec!["--max-error", "--seams"])
        );
        // Reached: nothing to say.
        let mut o = short(Stop::Target, &[("sliver", 5)], 0, 0);
        o.target_reached = true;
        assert_eq!(advise(&o, "a", "b"), None);
    }

    /// A limit already relaxed to the example's value is not advised again.
    #[test]
    fn advice_relaxes_the_limits_in_use() {
        let o = short(
            Stop::NoLegalCollapse,
            &[("normal_turn", 900), ("sliver", 40)],
            0,
            0,
        );
        let a = advise(&o, "a", "b").unwrap();
        let examples = |a: &Advice| a.relax.iter().map(|r| r.example).collect::<Vec<_>>();
        assert_eq!(examples(&a), ["--max-turn 120", "--min-quality 0"]);
        let mut c = Config::new();
        c = c.with_max_normal_turn(120.0);
        c = c.with_min_quality(0.0);
        let a = advise(&o.clone().in_use(&c), "a", "b").unwrap();
        assert_eq!(examples(&a), ["--max-turn 179"]);
        c = c.with_max_normal_turn(179.0);
        let a = advise(&o.in_use(&c), "a", "b").unwrap();
        assert!(a.relax.is_empty(), "{:?}", a.relax);
    }

    /// A target of 0 triangles gets no fallback: no command would be worth running.
    #[test]
    fn no_fallback_to_zero_triangles() {
        let mut o = short(Stop::NoLegalCollapse, &[("sliver", 5)], 0, 0);
        o.target_triangles = 0;
        let a = advise(&o, "a", "b").unwrap();
        assert_eq!((&a.fallback, &a.fallback_then_collapse), (&None, &None));
        assert!(!a.text(&o, "").contains("--target-triangles 0"));
        assert_eq!(fallbacks("a", "b", 0), None);
        assert!(fallbacks("a", "b", 1).is_some());
    }

    /// A real run held back by a tight normal-turn limit: the report names it.
    #[test]
    fn a_real_report_names_its_limit() {
        let n = 24u32;
        let w = n + 1;
        let positions = (0..w * w)
            .map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                [x, y, (x * 0.7).sin() * (y * 0.5).cos() * 2.0]
            })
            .collect();
        let mut triangles = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let a = y * w + x;
                triangles.extend([[a, a + 1, a + w + 1], [a, a + w + 1, a + w]]);
            }
        }
        let mesh = crate::io::MeshData {
            positions,
            triangles,
        };
        let mut config = Config::new().with_ratio(0.05);
        config = config.with_max_normal_turn(2.0);
        let (_, report, _) = crate::simplify::simplify(&mesh, &config).expect("simplify");
        assert!(!report.target_reached, "{report:?}");
        let o = Outcome::from(&report);
        let a = advise(&o, "in.obj", "out.obj").expect("stopped short");
        assert_eq!(a.limit, "normal_turn", "{report:?}");
        assert_eq!(a.relax[0].option, "--max-turn");
        // Relaxed, it gets there.
        config = config.with_max_normal_turn(120.0);
        let (_, report, _) = crate::simplify::simplify(&mesh, &config).expect("simplify");
        assert!(report.target_reached, "{report:?}");
        assert_eq!(advise(&Outcome::from(&report), "a", "b"), None);
    }
}

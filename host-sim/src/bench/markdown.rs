//! The benchmark as Markdown (`bench/RESULTS.md`): the summary, then one table per mesh.

use std::fmt::Write as _;

use super::{Method, Results, Row, WorstPair, MESSY_MESHES, REAL_WORLD_MESHES};
use crate::check::Validity;

/// Time in ms with 3 significant-ish digits.
fn fmt_ms(x: f64) -> String {
    if x >= 100.0 {
        format!("{x:.0}")
    } else if x >= 10.0 {
        format!("{x:.1}")
    } else if x >= 1.0 {
        format!("{x:.2}")
    } else {
        format!("{x:.3}")
    }
}

/// A ratio such as `0.74x` (`—` if it is not a number).
fn fmt_x(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.2}x")
    } else if x.is_nan() {
        "—".into()
    } else {
        "∞".into()
    }
}

/// A ratio as a percentage: `50 %`.
fn fmt_pct(r: f32) -> String {
    format!("{} %", (r as f64 * 100.0 * 1e3).round() / 1e3)
}

/// Short names of the checker's fields in the tables (anything else by its own name).
fn short_name(field: &str) -> String {
    match field {
        "new_non_manifold_edges" => "NM".into(),
        "duplicate_triangles" => "dup".into(),
        "degenerate_triangles" => "deg".into(),
        "new_folded_pairs" => "fold".into(),
        "out_of_range_triangles" => "range".into(),
        "boundary_loops" => "loops".into(),
        "euler" => "χ".into(),
        "new_pinched_vertices" => "pinch".into(),
        "new_zero_area_triangles" => "zero-area".into(),
        "new_vertices" => "new vertices".into(),
        "new_boundary_vertices" => "new boundary vertices".into(),
        other => other.replace('_', " "),
    }
}

/// The checker's verdict in one cell: `yes`, or `**NO**` and what differs: every non-zero
/// count and every changed before/after pair of [`Validity`], read through its serialised
/// form, so that new checks show up here without changes. The topology pairs (boundary loops,
/// Euler characteristic) are left out when the checker says it did not compare them
/// (`topology_compared: false`, a non-manifold input).
pub fn verdict(v: &Validity) -> String {
    if v.is_valid() {
        return "yes".into();
    }
    let mut parts = Vec::new();
    if let Ok(serde_json::Value::Object(map)) = serde_json::to_value(v) {
        let compared = map
            .get("topology_compared")
            .and_then(serde_json::Value::as_bool)
            .unwrap_or(true);
        for (k, x) in &map {
            match x {
                serde_json::Value::Number(n) if n.as_f64() != Some(0.0) => {
                    parts.push(format!("{} {n}", short_name(k)))
                }
                serde_json::Value::Array(a)
                    if a.len() == 2
                        && a[0] != a[1]
                        && (compared || !matches!(k.as_str(), "boundary_loops" | "euler")) =>
                {
                    parts.push(format!("{} {}→{}", short_name(k), a[0], a[1]))
                }
                _ => {}
            }
        }
    }
    if parts.is_empty() {
        "**NO**".into()
    } else {
        format!("**NO** ({})", parts.join(", "))
    }
}

/// Mesh names in first-appearance order.
fn mesh_names(r: &Results) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for row in &r.rows {
        if !names.contains(&row.mesh.as_str()) {
            names.push(&row.mesh);
        }
    }
    names
}

/// The results as Markdown: a header, the summary, where the library stopped short, then one
/// table per mesh.
pub fn markdown(r: &Results) -> String {
    let mut s = String::new();
    header(&mut s, r);
    summary(&mut s, r);
    stopped_short(&mut s, r);
    integer(&mut s, r);
    per_mesh(&mut s, r);
    s
}

/// The integer path against the float path of the same mode, mesh and ratio: Metro mean and
/// Hausdorff distance, all against the input, of the float run on the input, of the float run
/// on the integer run's grid, and of the integer run; each row's ratios, and per mode the
/// geometric mean and the worst row of each. Nothing when the run had no integer mode.
fn integer(s: &mut String, r: &Results) {
    let find = |row: &Row, m: Method| {
        r.rows
            .iter()
            .find(|x| x.mesh == row.mesh && x.ratio == row.ratio && x.method == m)
    };
    let mut lines = Vec::new();
    let mut totals = Vec::new();
    let mut floors = Vec::new();
    for int in [Method::FastInteger, Method::LeanInteger] {
        // The float run mirrored over the float run: the geometric mean of each ratio and the
        // largest spread either way.
        let (mut mirror_logs, mut spread) =
            ([0.0f64; 2], [(0.0f64, String::new()), (0.0, String::new())]);
        // Ratios: mean and max over the float run, then over the float run on the grid.
        let mut logs = [0.0f64; 4];
        let mut worst = [
            (0.0f64, String::new()),
            (0.0, String::new()),
            (0.0, String::new()),
            (0.0, String::new()),
        ];
        let mut n = 0;
        for row in r.rows.iter().filter(|x| x.method == int) {
            let (Some(f), Some(g)) = (find(row, int.float()), row.float_on_grid) else {
                continue;
            };
            let q = [
                row.metro_mean_pct / f.metro_mean_pct,
                row.metro_max_pct / f.metro_max_pct,
                row.metro_mean_pct / g[0],
                row.metro_max_pct / g[1],
            ];
            let at = format!("{} {}", row.mesh, fmt_pct(row.ratio));
            let m = row
                .float_mirrored
                .map_or([f64::NAN; 2], |m| [m[0] / g[0], m[1] / g[1]]);
            for k in 0..2 {
                mirror_logs[k] += m[k].ln();
                let far = m[k].max(1.0 / m[k]);
                if far > spread[k].0 {
                    spread[k] = (far, at.clone());
                }
            }
            for k in 0..4 {
                logs[k] += q[k].ln();
                if q[k] > worst[k].0 {
                    worst[k] = (q[k], at.clone());
                }
            }
            n += 1;
            lines.push(format!(
                "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {} | {} | {} |",
                row.mesh,
                fmt_pct(row.ratio),
                // The pipeline's mode name, not a table label (those count rows per mode).
                int.pipeline().map_or("", |p| p.name()),
                f.metro_mean_pct,
                g[0],
                row.metro_mean_pct,
                fmt_x(q[0]),
                fmt_x(q[2]),
                fmt_x(m[0]),
                f.metro_max_pct,
                g[1],
                row.metro_max_pct,
                fmt_x(q[1]),
                fmt_x(q[3]),
                fmt_x(m[1])
            ));
        }
        if n > 0 {
            // A geometric mean from its sum of logs, then the worst ratio and its run.
            let summary = |log: f64, (x, at): &(f64, String)| {
                format!("{} | {} ({at})", fmt_x((log / n as f64).exp()), fmt_x(*x))
            };
            let cell = |k: usize| summary(logs[k], &worst[k]);
            totals.push(format!(
                "| {} | {} | {} | {} | {} | {} |",
                int.label(),
                n,
                cell(2),
                cell(3),
                cell(0),
                cell(1)
            ));
            let mirrored = |k: usize| summary(mirror_logs[k], &spread[k]);
            floors.push(format!(
                "| {} | {} | {} | {} |",
                int.float().label(),
                n,
                mirrored(0),
                mirrored(1)
            ));
        }
    }
    if totals.is_empty() {
        return;
    }
    let _ = writeln!(s, "\n## Integer against float\n");
    let _ = writeln!(
        s,
        "Each integer run against the float run of the same mode, mesh and ratio on the same \
         grid mesh (the integer run's input: the arithmetic's own cost), and against the float \
         run on the input (the grid's rounding too, at most half a cell's diagonal a vertex). \
         Metro's symmetric mean and Hausdorff distance, % of the input's diagonal, all against \
         the input; geometric means over the runs and the worst run.\n"
    );
    let _ = writeln!(
        s,
        "| mode | runs | mean × float on the grid | worst | max × float on the grid | worst | mean × float | worst | max × float | worst |"
    );
    let _ = writeln!(s, "|---|---:|---:|---|---:|---|---:|---|---:|---|");
    for t in totals {
        let _ = writeln!(s, "{t}");
    }
    let _ = writeln!(
        s,
        "\nThe floor of a row's comparison: the float run on the grid mesh mirrored (x negated, \
         winding reversed, the output mirrored back: the same surface, exactly, in other floats) \
         against the float run on the grid mesh. Geometric mean of the ratio, and the largest \
         ratio either way (the larger of x and 1/x) and its run.\n"
    );
    let _ = writeln!(
        s,
        "| float mode | runs | mean × unmirrored | largest either way | max × unmirrored | largest either way |"
    );
    let _ = writeln!(s, "|---|---:|---:|---|---:|---|");
    for f in floors {
        let _ = writeln!(s, "{f}");
    }
    let _ = writeln!(
        s,
        "\n| mesh | ratio | mode | float mean % | float on the grid | integer | × float | × on the grid | mirrored × on the grid | float max % | float on the grid | integer | × float | × on the grid | mirrored × on the grid |"
    );
    let _ = writeln!(
        s,
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for l in lines {
        let _ = writeln!(s, "{l}");
    }
}

/// The title, the command, the machine, the modes and how they were measured.
fn header(s: &mut String, r: &Results) {
    let _ = writeln!(s, "# tinydecimate vs meshoptimizer\n");
    let _ = writeln!(s, "Written by `host-sim bench` (host-sim/src/bench.rs).\n");
    let _ = writeln!(s, "* Command: `{}`", r.command);
    let _ = writeln!(
        s,
        "* Machine: {}; shared with other jobs, so the timings are indicative only.",
        r.machine
    );
    let _ = writeln!(
        s,
        "* meshoptimizer {} (bundled by the `meshopt` crate {}): `meshopt::simplify`, target \
         index count 3·⌊ratio·T⌋, target error 1.0 (no limit), default options. On a mesh with \
         vertices split at one position (seams), meshoptimizer gets the mesh welded by \
         position, the surface ours simplifies: on the split mesh it locks every position with \
         more than two wedges and keeps nearly every triangle of a flat-shaded model.",
        r.meshoptimizer_version, r.meshopt_crate_version
    );
    let modes: Vec<String> = Method::ALL
        .iter()
        .filter(|m| m.is_ours())
        .map(|m| format!("{} = {}", m.label(), m.config_text()))
        .collect();
    let _ = writeln!(
        s,
        "* tinydecimate modes, each `.with_ratio(ratio)`: {}. As `tinydecimate simplify` runs \
         them: vertices at one position welded (`--seams weld`), the greedy modes (vertex \
         decimation too) with the error limit of 2 % of the diagonal (`--error-limit`); the \
         greedy, batched, fast and lean modes, unless the bench was given `--parts keep`, \
         with parts pruned (`--parts prune`; the fast and lean modes by \
         `Config::prune_parts`); vertex decimation welded by position without wedges \
         (positions only) and without part pruning (a removal has no collapse cost to weigh a \
         part against).",
        modes.join("; ")
    );
    let ratios: Vec<String> = r.ratios.iter().map(|x| fmt_pct(*x)).collect();
    let _ = writeln!(
        s,
        "* Meshes: `{}`; ratios {}; {} repetition(s) per run, each on a fresh copy of the \
         input; Metro with {} face samples per triangle.",
        r.meshes.replace(", ", "`, `"),
        ratios.join(", "),
        r.reps,
        r.samples_per_triangle
    );
    let _ = writeln!(
        s,
        "* **Same triangle count.** When a mode of ours stops above its target (no legal \
         collapse left, e.g. on locked non-manifold parts), meshoptimizer runs again with the \
         triangle count we reached as its target, and that mode's error ratios (marked †) are \
         taken against this run, not against meshoptimizer at the original target."
    );
}

/// The summary: per mode against meshoptimizer, time and error, and the invalid outputs.
fn summary(s: &mut String, r: &Results) {
    let time_ratios: Vec<String> = r.summary.time_ratios.iter().map(|x| fmt_pct(*x)).collect();
    let _ = writeln!(s, "\n## Summary\n");
    let _ = writeln!(
        s,
        "| mode | valid | target reached | time × mopt (geo. mean, {}) | scratch B/tri |",
        time_ratios.join(" & ")
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|");
    for m in &r.summary.modes {
        let (lo, hi) = m.scratch_bytes_per_triangle;
        let bpt = if (hi - lo).abs() < 0.05 {
            format!("{hi:.1}")
        } else {
            format!("{lo:.1}-{hi:.1}")
        };
        let _ = writeln!(
            s,
            "| {} | {}/{} | {}/{} | {} | {bpt} |",
            m.method.label(),
            m.valid,
            m.runs,
            m.target_reached,
            m.runs,
            fmt_x(m.time_vs_meshopt_geomean),
        );
    }
    if r.summary.same_count_runs > 0 {
        let _ = writeln!(
            s,
            "| meshoptimizer at our reached counts | {}/{} | | | |",
            r.summary.same_count_valid, r.summary.same_count_runs
        );
    }
    let _ = writeln!(
        s,
        "\nMetro error against meshoptimizer at the same count over every mesh and ratio (the \
         same-count run where a mode stopped short): geometric means of the mean and max \
         (Hausdorff) ratios, and the worst row of each.\n"
    );
    let _ = writeln!(
        s,
        "| mode | mean × mopt (geo. mean) | max × mopt (geo. mean) | worst mean × mopt | worst max × mopt |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|");
    for m in &r.summary.modes {
        if let Some(o) = &m.overall {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} ({} {}) | {} ({} {}) |",
                m.method.label(),
                fmt_x(o.mean_geomean),
                fmt_x(o.max_geomean),
                fmt_x(o.worst.mean_vs_meshopt),
                o.worst.mean_mesh,
                fmt_pct(o.worst_at.0),
                fmt_x(o.worst.max_vs_meshopt),
                o.worst.max_mesh,
                fmt_pct(o.worst_at.1),
            );
        }
    }
    let messy: Vec<&str> = MESSY_MESHES
        .iter()
        .map(|m| m.trim_end_matches(".obj"))
        .collect();
    let real: Vec<&str> = REAL_WORLD_MESHES
        .iter()
        .map(|m| m.trim_end_matches(".obj"))
        .collect();
    let _ = writeln!(
        s,
        "\nWorst error ratio vs meshoptimizer over the meshes, per mode and ratio, and the mesh \
         it is on; † at the same triangle count (the mode stopped short there). Clean meshes: \
         all but the messy multi-part ones ({}) and the real-world ones ({}); the targets are \
         ≤ 0.8x mean and ≤ 1.0x max of the default there (paper passes: ≤ 2.0x mean), ≤ 1.5x \
         at the same count on the messy ones and ≤ 1.0x on the real-world ones.\n",
        messy.join(", "),
        real.join(", ")
    );
    let _ = writeln!(
        s,
        "| mode | ratio | mean × mopt, clean | max × mopt, clean | mean × mopt, messy | max × mopt, messy | mean × mopt, real-world | max × mopt, real-world |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|");
    let cell = |x: f64, dag: bool, mesh: &str| {
        format!(
            "{}{} ({})",
            fmt_x(x),
            if dag { "†" } else { "" },
            mesh.trim_end_matches(".obj")
        )
    };
    for m in &r.summary.modes {
        for w in &m.worst {
            let pair = |p: &Option<WorstPair>| match p {
                Some(p) => (
                    cell(p.mean_vs_meshopt, p.mean_same_count, &p.mean_mesh),
                    cell(p.max_vs_meshopt, p.max_same_count, &p.max_mesh),
                ),
                None => ("—".into(), "—".into()),
            };
            let (cm, cx) = pair(&w.clean);
            let (mm, mx) = pair(&w.messy);
            let (rm, rx) = pair(&w.real_world);
            let _ = writeln!(
                s,
                "| {} | {} | {cm} | {cx} | {mm} | {mx} | {rm} | {rx} |",
                m.method.label(),
                fmt_pct(w.ratio),
            );
        }
    }
    let invalid: Vec<String> = r
        .rows
        .iter()
        .filter(|x| !x.valid)
        .map(|x| format!("{} {} @ {}", x.method.label(), x.mesh, fmt_pct(x.ratio)))
        .collect();
    if !invalid.is_empty() {
        let _ = writeln!(s, "\nInvalid results: {}.", invalid.join("; "));
    }
}

/// The runs where the library stopped above its target, compared at the same count.
fn stopped_short(s: &mut String, r: &Results) {
    let short: Vec<&Row> = r.rows.iter().filter(|x| x.same_count.is_some()).collect();
    let _ = writeln!(s, "\n## Stopped short\n");
    if short.is_empty() {
        let _ = writeln!(s, "Every mode reached every target.");
    } else {
        let _ = writeln!(
            s,
            "Runs of ours that stopped above the target, why (the report's `stop`, locked \
             vertices and refused candidates by reason, counted once per evaluation), and \
             meshoptimizer at the count we reached.\n"
        );
        let _ = writeln!(
            s,
            "| mesh | ratio | mode | target | reached | stop | locked vertices | rejected | \
             mopt tris | mean % | mopt mean % | × | max % | mopt max % | × | mopt valid |"
        );
        let _ = writeln!(
            s,
            "|---|---:|---|---:|---:|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|"
        );
        for x in short {
            let (Some(c), Some(rep)) = (&x.same_count, &x.report) else {
                continue;
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} ({:.1} %) | {} | {} | {} | {} | {:.4} | {:.4} | {} | \
                 {:.3} | {:.3} | {} | {} |",
                x.mesh,
                fmt_pct(x.ratio),
                x.method.label(),
                x.target_triangles,
                x.triangles_out,
                100.0 * x.triangles_out as f64 / x.triangles_in.max(1) as f64,
                rep.stop,
                rep.locked_vertices,
                rep.rejected.text(),
                c.triangles_out,
                x.metro_mean_pct,
                c.metro_mean_pct,
                fmt_x(c.mean_vs_meshopt),
                x.metro_max_pct,
                c.metro_max_pct,
                fmt_x(c.max_vs_meshopt),
                verdict(&c.validity),
            );
        }
    }
}

/// One table per mesh: every mode at every ratio.
fn per_mesh(s: &mut String, r: &Results) {
    let _ = writeln!(
        s,
        "\nPer mesh: **tris** triangles reached (target ⌊ratio·T⌋; *short* if above it); **ms** \
         median wall time of the simplifier call, **× mopt** over meshoptimizer's; **B/tri** \
         scratch bytes per input triangle (tinydecimate: exact right-sized `Workspace`, from \
         `Workspace::BYTES`; meshoptimizer: peak of its temporary allocations, counted with \
         `meshopt_setAllocator`, output index buffer not counted); **mean %** / **max %** \
         Metro symmetric mean and Hausdorff distance in % of the input's bbox diagonal, each \
         followed by its ratio to meshoptimizer's († at the same triangle count: see the \
         *meshoptimizer at N* row below it); **valid** the shared checker's verdict \
         (`tinydecimate check`; NM new non-manifold edges, dup duplicate and deg degenerate \
         triangles, fold new folded pairs, loops boundary loops and χ Euler characteristic \
         before→after); **stop** the library's `Report::stop`."
    );
    for name in mesh_names(r) {
        let rows: Vec<&Row> = r.rows.iter().filter(|x| x.mesh == name).collect();
        let _ = writeln!(
            s,
            "\n## {name} (V = {}, T = {})\n",
            rows[0].vertices, rows[0].triangles_in
        );
        let _ = writeln!(
            s,
            "| ratio | mode | tris | ms | × mopt | B/tri | mean % | × mopt | max % | × mopt | valid | stop |"
        );
        let _ = writeln!(
            s,
            "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---|"
        );
        for x in rows {
            let dag = if x.same_count.is_some() { "†" } else { "" };
            let _ = writeln!(
                s,
                "| {} | {} | {}{} | {} | {} | {:.1} | {:.4} | {}{dag} | {:.3} | {}{dag} | {} | {} |",
                fmt_pct(x.ratio),
                x.method.label(),
                x.triangles_out,
                if x.target_reached {
                    String::new()
                } else {
                    format!(" (short; target {})", x.target_triangles)
                },
                fmt_ms(x.median_ms),
                fmt_x(x.time_vs_meshopt),
                x.scratch_bytes_per_triangle,
                x.metro_mean_pct,
                fmt_x(x.fair_mean_vs_meshopt()),
                x.metro_max_pct,
                fmt_x(x.fair_max_vs_meshopt()),
                verdict(&x.validity),
                x.stop.as_deref().unwrap_or("—"),
            );
            if let Some(c) = &x.same_count {
                let _ = writeln!(
                    s,
                    "| {} | meshoptimizer at {} | {} | {} | | | {:.4} | | {:.3} | | {} | same count as {} |",
                    fmt_pct(x.ratio),
                    c.target_triangles,
                    c.triangles_out,
                    fmt_ms(c.median_ms),
                    c.metro_mean_pct,
                    c.metro_max_pct,
                    verdict(&c.validity),
                    x.method.label(),
                );
            }
        }
    }
}

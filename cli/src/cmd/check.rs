//! `tinydecimate check ORIGINAL SIMPLIFIED`: the topology of both meshes and whether the second is a
//! valid simplification of the first ([`crate::check::verdict`], the function behind
//! `simplify`'s own verdict, under the same promises with the same defaults), as text or JSON.

use super::simplify::{PartsArg, PlacementArg, SeamsArg};
use crate::check::{analyse, part_verdicts, verdict, Promise};

/// `tinydecimate check ORIGINAL SIMPLIFIED`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// The input mesh (`-`: standard input).
    pub original: std::path::PathBuf,
    /// The simplified mesh: the input's vertex numbering, or a file `tinydecimate simplify` wrote
    /// with unreferenced vertices dropped (matched back by position, see `renumbered`).
    pub simplified: std::path::PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// How the simplified mesh was placed: `optimal` allows kept vertices to have moved
    /// (`simplify --quadric stored --placement optimal`); its vertices are then matched to the
    /// input's by index, so the file must keep the input's numbering (as simplify writes it
    /// with optimal placement), never by position.
    #[arg(long, value_enum, default_value_t = PlacementArg::Subset)]
    pub placement: PlacementArg,
    /// As `simplify --seams`: `weld` (simplify's default) compares both meshes welded by
    /// position, so vertices split on a seam are one vertex and a seam pulled apart is a
    /// crack; `split` compares the files' own vertices, every seam an open boundary.
    #[arg(long, value_enum, default_value_t = SeamsArg::Weld)]
    pub seams: SeamsArg,
    /// As `simplify --parts`: `prune` (simplify's default) accepts a part of the original
    /// that is gone whole; `keep` counts it as a changed number of components.
    #[arg(long, value_enum, default_value_t = PartsArg::Prune)]
    pub parts: PartsArg,
    /// As `simplify --per-primitive`: judge each glTF primitive (each OBJ material group with
    /// attributes) on its own, as such a run simplified them, with the whole surface's verdict
    /// beside it. Without it the file is judged as one surface, as `simplify` simplifies the
    /// parts of a mesh together: a border between parts that opened is a defect.
    #[arg(long)]
    pub per_primitive: bool,
}

/// `tinydecimate check`: topology of both meshes and the validity; exit code 1 if invalid.
pub fn run(args: &Args) -> anyhow::Result<std::process::ExitCode> {
    let a = crate::io::load_noting(&args.original)?;
    let b = crate::io::load_noting(&args.simplified)?;
    let promise = Promise {
        moved: args.placement == PlacementArg::Optimal,
        welded: args.seams == SeamsArg::Weld,
        parts: args.parts == PartsArg::Prune,
    };
    let (b, note, v) = verdict(&a, &b, promise)?;
    let (ta, tb) = (analyse(&a), analyse(&b));
    // A file of several parts (glTF primitives, OBJ material groups with attributes) that
    // `simplify --per-primitive` simplified part by part is judged the same way; the whole
    // surface's verdict is reported beside it, since borders between parts open then.
    let parts = if args.per_primitive {
        part_verdicts(&args.original, &args.simplified, promise)?
    } else {
        None
    };
    let valid = match &parts {
        Some(ps) => ps.iter().all(|p| p.validity.is_valid()),
        None => v.is_valid(),
    };
    if args.json {
        let part_json = parts.as_ref().map(|ps| {
            ps.iter()
                .map(|p| {
                    serde_json::json!({
                        "part": p.label,
                        "renumbered": p.note,
                        "valid": p.validity.is_valid(),
                        "defects": p.validity.defects.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
                    })
                })
                .collect::<Vec<_>>()
        });
        let j = serde_json::json!({
            "original": ta,
            "simplified": tb,
            "renumbered": note,
            "seams": args.seams,
            "parts": args.parts,
            "validity": v,
            "defects": v.defects.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
            "judged_by_part": part_json,
            "valid": valid,
        });
        crate::outln!("{}", serde_json::to_string_pretty(&j)?);
    } else {
        crate::outln!("original {}:\n{ta}", args.original.display());
        crate::outln!("simplified {}:\n{tb}", args.simplified.display());
        if let Some(n) = note {
            crate::outln!("note: {n}");
        }
        match &parts {
            None => crate::outln!("validity ({}):\n{v}", against(promise)),
            Some(ps) => {
                crate::outln!(
                    "validity, each of the {} parts on its own as simplify --per-primitive \
                     judges them ({}):",
                    ps.len(),
                    against(promise)
                );
                for p in ps {
                    let mark = if p.validity.is_valid() {
                        "valid"
                    } else {
                        "NOT valid"
                    };
                    crate::outln!("  {}: {mark}", p.label);
                    for d in p.validity.describe_by_kind(3).lines() {
                        crate::outln!("    {d}");
                    }
                }
                let whole = if v.is_valid() {
                    "valid".to_string()
                } else {
                    format!(
                        "{} defects, where borders between parts opened: each part was \
                         simplified on its own",
                        v.defects.len()
                    )
                };
                crate::outln!("  the parts as one surface: {whole}");
                crate::outln!("  => {}", if valid { "VALID" } else { "INVALID" });
            }
        }
    }
    Ok(if valid {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::from(1)
    })
}

/// What the verdict compares, in words.
pub fn against(p: Promise) -> String {
    let mut s = String::from(
        "against the cleaned original: degenerate and duplicate triangles dropped as the \
         library does",
    );
    if p.welded {
        s += "; both welded by position (--seams weld), vertex numbers the original's first at \
              each position";
    } else {
        s += "; the files' own vertices (--seams split)";
    }
    s += if p.parts {
        "; parts gone whole allowed (--parts prune)"
    } else {
        "; every part kept (--parts keep)"
    };
    if p.moved {
        s += "; kept vertices may have moved";
    }
    s
}

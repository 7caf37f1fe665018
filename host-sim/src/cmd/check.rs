//! `host-sim check ORIGINAL SIMPLIFIED`: the topology of both meshes and whether the second is a
//! valid simplification of the first ([`crate::check::verdict`]), as text or JSON.

use crate::check::{analyse, verdict};

/// `host-sim check ORIGINAL SIMPLIFIED`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// The input mesh (`-`: standard input).
    pub original: std::path::PathBuf,
    /// The simplified mesh: the input's vertex numbering, or a file `host-sim simplify` wrote
    /// with unreferenced vertices dropped (matched back by position, see `renumbered`).
    pub simplified: std::path::PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// How the simplified mesh was placed: `optimal` allows kept vertices to have moved
    /// (`simplify --quadric stored --placement optimal`); its vertices are then matched to the
    /// input's by index, so the file must keep the input's numbering (as simplify writes it
    /// with optimal placement), never by position.
    #[arg(long, value_enum, default_value_t = super::simplify::PlacementArg::Subset)]
    pub placement: super::simplify::PlacementArg,
}

/// `host-sim check`: topology of both meshes and the validity; exit code 1 if invalid.
pub fn run(args: &Args) -> anyhow::Result<std::process::ExitCode> {
    let a = crate::io::load_noting(&args.original)?;
    let b = crate::io::load_noting(&args.simplified)?;
    let moved = args.placement == super::simplify::PlacementArg::Optimal;
    let (b, note, v) = verdict(&a, &b, moved)?;
    let (ta, tb) = (analyse(&a), analyse(&b));
    if args.json {
        let j = serde_json::json!({
            "original": ta,
            "simplified": tb,
            "renumbered": note,
            "validity": v,
            "defects": v.defects.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
            "valid": v.is_valid(),
        });
        crate::outln!("{}", serde_json::to_string_pretty(&j)?);
    } else {
        crate::outln!("original {}:\n{ta}", args.original.display());
        crate::outln!("simplified {}:\n{tb}", args.simplified.display());
        if let Some(n) = note {
            crate::outln!("note: {n}");
        }
        crate::outln!("validity (against the cleaned original: degenerate and duplicate triangles dropped as the library does{}):\n{v}", if moved { "; kept vertices may have moved" } else { "" });
    }
    Ok(if v.is_valid() {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::from(1)
    })
}

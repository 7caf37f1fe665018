//! `tinydecimate render MESH OUT.png [--compare ORIGINAL]`: a flat-shaded picture of a mesh, or a
//! comparison with error heatmaps both ways ([`crate::render::draw`]).

use anyhow::Result;

use crate::render::draw;

/// `tinydecimate render MESH OUT.png [--compare ORIGINAL]`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// The mesh to draw.
    pub mesh: std::path::PathBuf,
    /// Output PNG.
    pub out: std::path::PathBuf,
    /// Draw original | MESH | ORIGINAL coloured by its distance to MESH (surface MESH lost is
    /// hot) | MESH coloured by its distance to ORIGINAL, side by side, both heatmaps on one scale.
    /// glTF models: original | MESH | MESH with its edges, textured.
    #[arg(long, value_name = "ORIGINAL")]
    pub compare: Option<std::path::PathBuf>,
}

/// `tinydecimate render`.
pub fn run(args: &Args) -> Result<std::process::ExitCode> {
    draw(&args.mesh, &args.out, args.compare.as_deref())?;
    Ok(std::process::ExitCode::SUCCESS)
}

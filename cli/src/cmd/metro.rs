//! `tinydecimate metro ORIGINAL SIMPLIFIED`: the Metro surface distance between two meshes
//! ([`crate::metro::metro`]), as text or JSON.

use crate::metro::{metro, MetroOptions};

/// `tinydecimate metro ORIGINAL SIMPLIFIED`
#[derive(Clone, Debug, clap::Args)]
pub struct Args {
    /// The original mesh (its bbox diagonal is the unit of the percentages).
    pub original: std::path::PathBuf,
    /// The simplified mesh.
    pub simplified: std::path::PathBuf,
    /// Face samples per triangle of the larger mesh (edge samples: a quarter of that).
    #[arg(long, default_value_t = 10.0)]
    pub samples_per_triangle: f64,
    /// Seed of the sampling RNG.
    #[arg(long, default_value_t = MetroOptions::default().seed)]
    pub seed: u64,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `tinydecimate metro`.
pub fn run(args: &Args) -> anyhow::Result<std::process::ExitCode> {
    if !(args.samples_per_triangle.is_finite() && args.samples_per_triangle > 0.0) {
        anyhow::bail!("--samples-per-triangle must be a positive number");
    }
    let a = crate::io::load_noting(&args.original)?;
    let b = crate::io::load_noting(&args.simplified)?;
    let opts = MetroOptions {
        samples_per_triangle: args.samples_per_triangle,
        seed: args.seed,
        progress: true,
    };
    let start = std::time::Instant::now();
    let r = metro(&a, &b, &opts);
    if args.json {
        crate::outln!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        crate::outln!(
            "metro {} vs {}:",
            args.original.display(),
            args.simplified.display()
        );
        // The counts the files were read with (a glTF: every primitive once, as `simplify`
        // counts them).
        crate::outln!(
            "  triangles                {} (original), {} (simplified)",
            a.triangles.len(),
            b.triangles.len()
        );
        crate::outln!("{r}");
        crate::outln!(
            "  time                     {:.2} s",
            start.elapsed().as_secs_f64()
        );
    }
    Ok(std::process::ExitCode::SUCCESS)
}

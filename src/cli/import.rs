//! `peopletrack import wildtrack DIR -o FILE.mcap [--detector-noise drop=…,jitter=…,false=…]`:
//! a public dataset as a session log, optionally through the detector model
//! ([`peopletrack::log::import`]).

use std::path::PathBuf;

use peopletrack::log::import::detector_noise::DetectorNoise;
use peopletrack::log::import::wildtrack::{self, Intrinsics};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub dataset: Dataset,
}

#[derive(Debug, clap::Subcommand)]
pub enum Dataset {
    /// WILDTRACK (7 calibrated cameras, annotated boxes and ground positions): DIR holds
    /// `calibrations/` and `annotations_positions/`.
    Wildtrack {
        /// The dataset folder, e.g. ../shared/real/wildtrack.
        dir: PathBuf,
        /// The session log to write.
        #[arg(short = 'o', long = "out", value_name = "FILE.mcap")]
        out: PathBuf,
        /// Use `intrinsic_original` (raw-video distortion) instead of `intrinsic_zero` (the
        /// undistorted images the boxes were annotated on).
        #[arg(long)]
        original_intrinsics: bool,
        /// Pass the annotated boxes through the detector model of our own before writing them
        /// (`drop=0.2,jitter=0.04,false=1`: miss probability, edge noise as a fraction of the
        /// box height, mean false person-shaped boxes per camera frame; the ground truth stays
        /// the annotation).
        #[arg(long, value_name = "drop=P,jitter=F,false=N")]
        detector_noise: Option<String>,
        /// Seed of the detector model's draws.
        #[arg(long, default_value_t = 1)]
        noise_seed: u64,
    },
}

pub fn run(a: &Args, out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    match &a.dataset {
        Dataset::Wildtrack {
            dir,
            out: file,
            original_intrinsics,
            detector_noise,
            noise_seed,
        } => {
            let noise = detector_noise
                .as_deref()
                .map(DetectorNoise::parse)
                .transpose()
                .map_err(|e| anyhow::anyhow!("--detector-noise: {e}"))?;
            let intr = if *original_intrinsics {
                Intrinsics::Original
            } else {
                Intrinsics::Zero
            };
            // which intrinsics the boxes fit: measured on both sets, printed for the user
            for check in [Intrinsics::Zero, Intrinsics::Original] {
                let ds = wildtrack::read(dir, check)?;
                let c = wildtrack::projection_check(&ds);
                writeln!(
                    out,
                    "{}: {} boxes; ground point to box bottom: median {:.1} px (p90 {:.1}); \
                     {:.1} m above it to box top: median {:.1} px",
                    check.folder(),
                    c.boxes,
                    c.median_foot_px,
                    c.p90_foot_px,
                    wildtrack::NOMINAL_HEIGHT_M,
                    c.median_head_px
                )?;
            }
            let ds = wildtrack::read(dir, intr)?;
            // the 3-D tracks' motion model (`accel_sigma_mps2`), from the development frames
            let dev = &ds.frames[..ds.frames.len().min(wildtrack::DEVELOPMENT_FRAMES)];
            if let Some(m) = wildtrack::motion_check(dev) {
                writeln!(
                    out,
                    "annotated people, frames 0–{}: {} second differences of position {:.2} s \
                     apart, median {:.3} m → white-noise acceleration σ {:.2} m/s²",
                    dev.len().saturating_sub(1),
                    m.samples,
                    m.period_s,
                    m.median_m,
                    m.accel_sigma_mps2
                )?;
            }
            if ds.skipped > 0 {
                writeln!(
                    out,
                    "skipped {} people: {}",
                    ds.skipped,
                    ds.first_skip.as_deref().unwrap_or("")
                )?;
            }
            let s = wildtrack::write_noisy(
                &ds,
                dir,
                intr,
                noise.as_ref().map(|n| (n, *noise_seed)),
                file,
            )?;
            writeln!(
                out,
                "{}: {} frames, {} person-frames, {} boxes in 7 cameras ({}; {} views not visible)",
                s.path.display(),
                s.frames,
                s.people_frames,
                s.boxes,
                intr.folder(),
                ds.invisible_views
            )?;
            if let Some(n) = &noise {
                writeln!(
                    out,
                    "detections through the detector model ({}; seed {noise_seed})",
                    n.label()
                )?;
            }
            Ok(())
        }
    }
}

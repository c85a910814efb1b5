//! Runs `vision::gmm::AdaptiveGmm` (OpenCV MOG2's defaults) over a sequence and writes the
//! exact frames it saw and the masks it produced, so `tools/opencv_mog2_agreement.py` can run
//! OpenCV on the same bytes and compare pixel by pixel.
//!
//! Usage:
//!   gmm_masks synthetic OUT_DIR [WIDTH HEIGHT FRAMES]        (default 320 240 300)
//!   gmm_masks synthetic-grey OUT_DIR [WIDTH HEIGHT FRAMES]   (the same scene in grey)
//!   gmm_masks wallflower WAVING_TREES_DIR OUT_DIR
//!
//! With `--stauffer-grimson` anywhere, the model is the fixed-M baseline
//! (`GmmParams::stauffer_grimson`) instead of OpenCV's defaults.
//!
//! OUT_DIR gets `frames.bin` (FRAMES x HEIGHT x WIDTH x CHANNELS bytes, the channel order the
//! model saw), `masks.bin` (FRAMES x HEIGHT x WIDTH), `meta.json` (shape and parameters) and, for
//! Wallflower, `truth.bin` (the hand-segmented mask of the evaluated frame, 0/255), plus
//! PNGs of the last mask, the background image and the components per pixel (fig. 2).

use std::fs;
use std::path::{Path, PathBuf};

use image::{GrayImage, RgbImage};
use peopletrack::vision::score::{MaskCounts, ShadowAs};
use peopletrack::vision::synthetic::Scene;
use peopletrack::vision::{AdaptiveGmm, GmmParams, ImageView};
use serde_json::json;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Wallflower protocol (WavingTrees/script.txt): frames 0–199 train, 200–247 run, evaluate
/// frame 247.
const WALLFLOWER_EVAL_FRAME: usize = 247;

fn main() -> Res<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let baseline = args.iter().any(|a| a == "--stauffer-grimson");
    args.retain(|a| a != "--stauffer-grimson");
    let params = if baseline {
        GmmParams::stauffer_grimson()
    } else {
        GmmParams::default()
    };
    let strs: Vec<&str> = args.iter().map(String::as_str).collect();
    match strs.as_slice() {
        [kind @ ("synthetic" | "synthetic-grey"), out, rest @ ..] => {
            let num = |i: usize, d: usize| -> Res<usize> {
                Ok(rest.get(i).map(|s| s.parse()).transpose()?.unwrap_or(d))
            };
            let scene = Scene {
                width: num(0, 320)?,
                height: num(1, 240)?,
                seed: 2004,
            };
            let mut frames: Vec<Vec<u8>> = (0..num(2, 300)?).map(|t| scene.frame(t)).collect();
            let channels = if *kind == "synthetic" { 3 } else { 1 };
            if channels == 1 {
                // Integer BT.601 luma; any fixed conversion will do, both sides see the bytes.
                for f in &mut frames {
                    *f = f
                        .chunks_exact(3)
                        .map(|p| {
                            let (r, g, b) = (u32::from(p[0]), u32::from(p[1]), u32::from(p[2]));
                            ((77 * r + 150 * g + 29 * b + 128) >> 8) as u8
                        })
                        .collect();
                }
            }
            let name = if baseline {
                format!("{kind} (Stauffer-Grimson)")
            } else {
                kind.to_string()
            };
            run(
                &name,
                params,
                &frames,
                (scene.width, scene.height, channels),
                None,
                Path::new(out),
            )
        }
        ["wallflower", dir, out] => {
            let dir = PathBuf::from(dir);
            let mut frames = Vec::new();
            let (mut w, mut h) = (0, 0);
            loop {
                let p = dir.join(format!("b{:05}.bmp", frames.len()));
                if !p.exists() {
                    break;
                }
                let img = image::open(&p)
                    .map_err(|e| format!("{}: {e}", p.display()))?
                    .to_rgb8();
                (w, h) = (img.width() as usize, img.height() as usize);
                frames.push(img.into_raw());
            }
            if frames.len() <= WALLFLOWER_EVAL_FRAME {
                return Err(format!("{}: only {} frames", dir.display(), frames.len()).into());
            }
            let gt_path = dir.join(format!("hand_segmented_{WALLFLOWER_EVAL_FRAME:05}.BMP"));
            let truth: Vec<u8> = image::open(&gt_path)
                .map_err(|e| format!("{}: {e}", gt_path.display()))?
                .to_rgb8()
                .pixels()
                .map(|p| if p.0.iter().any(|&v| v > 127) { 255 } else { 0 })
                .collect();
            run(
                "wallflower_waving_trees",
                params,
                &frames,
                (w, h, 3),
                Some((WALLFLOWER_EVAL_FRAME, truth)),
                Path::new(out),
            )
        }
        _ => Err(
            "usage: gmm_masks synthetic|synthetic-grey OUT_DIR [W H FRAMES] | gmm_masks wallflower DIR OUT_DIR"
                .into(),
        ),
    }
}

fn run(
    name: &str,
    params: GmmParams,
    frames: &[Vec<u8>],
    (width, height, channels): (usize, usize, usize),
    eval: Option<(usize, Vec<u8>)>,
    out: &Path,
) -> Res<()> {
    let mut gmm = AdaptiveGmm::new(params)?;
    let mut masks = vec![0u8; frames.len() * width * height];
    for (f, m) in frames.iter().zip(masks.chunks_exact_mut(width * height)) {
        gmm.apply(ImageView::new(f, width, height, channels)?, None, m)?;
    }
    fs::create_dir_all(out)?;
    fs::write(out.join("frames.bin"), frames.concat())?;
    fs::write(out.join("masks.bin"), &masks)?;
    let mut meta = json!({
        "name": name,
        "width": width,
        "height": height,
        "channels": channels,
        "frames": frames.len(),
        "params": params,
    });
    if let Some((k, truth)) = &eval {
        fs::write(out.join("truth.bin"), truth)?;
        meta["eval_frame"] = json!(k);
        let ours = &masks[k * width * height..(k + 1) * width * height];
        for (label, s) in [
            ("shadow as background", ShadowAs::Background),
            ("shadow as foreground", ShadowAs::Foreground),
        ] {
            let c = MaskCounts::count(ours, truth, s).ok_or("truth has another size")?;
            println!(
                "{name} frame {k}: ours F = {:.4} ({label}; precision {:.4}, recall {:.4}, FP {}, FN {})",
                c.f_measure(),
                c.precision(),
                c.recall(),
                c.false_positive,
                c.false_negative
            );
        }
    }
    fs::write(out.join("meta.json"), serde_json::to_string_pretty(&meta)?)?;

    // Pictures of the end state (the paper's fig. 2 shows components per pixel in grey).
    let last = &masks[(frames.len() - 1) * width * height..];
    let (w, h) = (width as u32, height as u32);
    GrayImage::from_raw(w, h, last.to_vec())
        .ok_or("mask size")?
        .save(out.join("last_mask.png"))?;
    let background = gmm.background_image()?;
    if channels == 3 {
        RgbImage::from_raw(w, h, background)
            .ok_or("background size")?
            .save(out.join("background.png"))?;
    } else {
        GrayImage::from_raw(w, h, background)
            .ok_or("background size")?
            .save(out.join("background.png"))?;
    }
    // Black: one component; white: all M in use.
    let top = (params.n_mixtures - 1).max(1);
    let comps: Vec<u8> = gmm
        .components_per_pixel()
        .iter()
        .map(|&n| (usize::from(n).saturating_sub(1) * 255 / top) as u8)
        .collect();
    GrayImage::from_raw(w, h, comps)
        .ok_or("components size")?
        .save(out.join("components.png"))?;
    println!(
        "{name}: {} frames {width}x{height} -> {}",
        frames.len(),
        out.display()
    );
    Ok(())
}

//! The adaptive GMM on the real Wallflower "WavingTrees" sequence (Toyama et al., ICCV 1999):
//! 160x120 BMPs of swaying trees, a person walks in at frame 242. Protocol (script.txt):
//! frames 0–199 train, 200–247 run, evaluate frame 247 against the hand-segmented mask.
//!
//! F-measure is reported with shadows (127) scored both ways. The assertion is a sanity bound,
//! not a tuned score: a mask that calls every pixel foreground scores F = 0.47 here (30.6 %
//! of the pixels are the person), so a working subtractor must clearly beat that; we require
//! F > 0.6 with shadows as background. What we measured is printed (run with --nocapture).
//! The MOG2-defaults model is also pinned to OpenCV's numbers at that frame (F = 0.9392,
//! FP 645, FN 102), which the README and the `wallflower` table claim.

use crate::common;

use peopletrack::vision::score::{MaskCounts, ShadowAs};
use peopletrack::vision::{AdaptiveGmm, GmmParams, ImageView};

const EVAL_FRAME: usize = 247;
/// Lowest acceptable F-measure (shadow as background); the all-foreground mask gets 0.47.
const MIN_F_MEASURE: f64 = 0.6;

fn load_rgb(path: &std::path::Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
}

#[test]
fn waving_trees_frame_247_f_measure() {
    let Some(dir) = common::real("wallflower_waving_trees/WavingTrees") else {
        return;
    };
    let truth: Vec<u8> = load_rgb(&dir.join("hand_segmented_00247.BMP"))
        .pixels()
        .map(|p| if p.0.iter().any(|&v| v > 127) { 255 } else { 0 })
        .collect();
    let all_fg = MaskCounts::count(&vec![255; truth.len()], &truth, ShadowAs::Background)
        .expect("same size")
        .f_measure();
    assert!((all_fg - 0.47).abs() < 0.01, "all-foreground F {all_fg}");

    for (name, params) in [
        ("Zivkovic (MOG2 defaults)", GmmParams::default()),
        (
            "Stauffer-Grimson (M = 4, c_T = 0)",
            GmmParams::stauffer_grimson(),
        ),
    ] {
        let mut gmm = AdaptiveGmm::new(params).expect("params");
        let mut mask = vec![0u8; truth.len()];
        for k in 0..=EVAL_FRAME {
            let img = load_rgb(&dir.join(format!("b{k:05}.bmp")));
            assert_eq!((img.width(), img.height()), (160, 120));
            let view = ImageView::rgb(&img).expect("frame");
            gmm.apply(view, None, &mut mask).expect("apply");
        }
        let bg = MaskCounts::count(&mask, &truth, ShadowAs::Background).expect("size");
        let fg = MaskCounts::count(&mask, &truth, ShadowAs::Foreground).expect("size");
        eprintln!(
            "{name}: frame {EVAL_FRAME} F = {:.4} shadow as background (FP {}, FN {}), \
             {:.4} shadow as foreground (FP {}, FN {})",
            bg.f_measure(),
            bg.false_positive,
            bg.false_negative,
            fg.f_measure(),
            fg.false_positive,
            fg.false_negative
        );
        assert!(
            bg.f_measure() > MIN_F_MEASURE,
            "{name}: F = {} is not above {MIN_F_MEASURE}",
            bg.f_measure()
        );
        if name.starts_with("Zivkovic") {
            // the pin: OpenCV 4.12 MOG2's own mask at this frame (tools/opencv_mog2_wallflower_f.py)
            // scores F = 0.9392 with FP 645, FN 102; ours is bit-identical, so exactly that
            assert_eq!((bg.false_positive, bg.false_negative), (645, 102), "{name}");
            assert_eq!(format!("{:.4}", bg.f_measure()), "0.9392", "{name}");
        }
    }
}

//! The adaptive GMM on the synthetic scene: masks do not depend on the thread count, and a
//! saved and restored model continues exactly as one never saved.

use peopletrack::vision::synthetic::Scene;
use peopletrack::vision::{AdaptiveGmm, GmmParams, ImageView};

const FRAMES: usize = 60;

/// A quarter of the benchmark size keeps the test quick in the dev profile; width 164 is
/// not a multiple of the 8-pixel lane groups, so the right-edge padding is exercised too.
fn scene() -> Scene {
    Scene {
        width: 164,
        height: 120,
        seed: 11,
    }
}

/// Masks of `frames` frames of the scene, computed inside a rayon pool of `threads`.
fn masks_with_threads(params: GmmParams, threads: usize) -> Vec<u8> {
    let s = scene();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| {
        let mut gmm = AdaptiveGmm::new(params).expect("params");
        let mut out = vec![0u8; FRAMES * s.width * s.height];
        for (t, mask) in out.chunks_exact_mut(s.width * s.height).enumerate() {
            let f = s.frame(t);
            let view = ImageView::new(&f, s.width, s.height, 3).expect("frame");
            gmm.apply(view, None, mask).expect("apply");
        }
        out
    })
}

#[test]
fn thread_count_does_not_change_the_masks() {
    for params in [GmmParams::default(), GmmParams::stauffer_grimson()] {
        let one = masks_with_threads(params, 1);
        let three = masks_with_threads(params, 3);
        assert!(one == three, "masks differ between 1 and 3 threads");
        // The scene exercises all three labels.
        for v in [0u8, 127, 255] {
            assert!(one.contains(&v), "no pixel labelled {v}");
        }
    }
}

#[test]
fn save_restore_continue_equals_never_saving() {
    let s = scene();
    let n = s.width * s.height;
    let mut straight = AdaptiveGmm::new(GmmParams::default()).expect("params");
    let mut saved = AdaptiveGmm::new(GmmParams::default()).expect("params");
    let (mut a, mut b) = (vec![0u8; n], vec![0u8; n]);
    let mut bytes = Vec::new();
    for t in 0..FRAMES {
        let f = s.frame(t);
        let view = ImageView::new(&f, s.width, s.height, 3).expect("frame");
        straight.apply(view, None, &mut a).expect("apply");
        saved.apply(view, None, &mut b).expect("apply");
        assert!(a == b, "frame {t}");
        if t % 20 == 19 {
            // Round-trip through bytes and carry on with the restored model.
            bytes.clear();
            saved.save(&mut bytes).expect("save");
            saved = AdaptiveGmm::load(&mut bytes.as_slice()).expect("load");
            assert_eq!(saved.frames_seen(), straight.frames_seen());
            assert_eq!(
                saved.components_per_pixel(),
                straight.components_per_pixel()
            );
        }
    }
    assert_eq!(
        saved.background_image().expect("seen"),
        straight.background_image().expect("seen")
    );
}

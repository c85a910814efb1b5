use super::*;

#[test]
fn xml_numbers_reads_plain_tags_and_opencv_matrices() {
    let text = "<?xml version=\"1.0\"?>\n<opencv_storage>\n<rvec>\n  1.5 -2 3e-1\n </rvec>\n\
        <camera_matrix type_id=\"opencv-matrix\">\n<rows>3</rows><cols>1</cols><dt>d</dt>\n\
        <data>1 0\n 2</data></camera_matrix>\n</opencv_storage>";
    assert_eq!(xml_numbers(text, "rvec"), Some(vec![1.5, -2.0, 0.3]));
    assert_eq!(
        xml_numbers(text, "camera_matrix"),
        Some(vec![1.0, 0.0, 2.0])
    );
    assert_eq!(xml_numbers(text, "tvec"), None);
    assert_eq!(xml_numbers("<rvec>1 nan</rvec>", "rvec"), None);
    assert_eq!(xml_numbers("<rvec>1 x</rvec>", "rvec"), None);
}

#[test]
fn ground_position_follows_the_readme_grid() {
    // README: X = -3.0 + 0.025 * (ID % 480), Y = -9.0 + 0.025 * (ID / 480)
    assert_eq!(ground_position(0), (-3.0, -9.0));
    let (x, y) = ground_position(360 * 480 + 120);
    assert!(
        (x - 0.0).abs() < 1e-12 && (y - 0.0).abs() < 1e-12,
        "{x} {y}"
    );
    let (x, y) = ground_position(POSITIONS - 1);
    assert!(
        (x - 8.975).abs() < 1e-9 && (y - 26.975).abs() < 1e-9,
        "{x} {y}"
    );
}

#[test]
fn median_of_even_and_odd_counts() {
    assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
    assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), Some(2.5));
    assert_eq!(median(vec![f64::NAN]), None);
}

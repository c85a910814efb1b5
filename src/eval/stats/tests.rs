//! Reference values: scipy 1.17.1, statsmodels 0.15.0, numpy 2.4.6, mpmath 1.4.1 (Python
//! 3.11), printed with `repr(float(..))`; the comment above each block names the calls.
use super::*;

/// Relative tolerance for agreement with the reference values (≥ 10 significant digits).
const REL: f64 = 1e-10;

/// Method A errors (n = 10, small spread).
const A: [f64; 10] = [
    0.126, 0.301, 0.087, 0.215, 0.412, 0.198, 0.054, 0.276, 0.333, 0.159,
];
/// Method B errors (n = 13, about twice A's standard deviation).
const B: [f64; 13] = [
    0.402, 0.118, 0.655, 0.287, 0.731, 0.049, 0.512, 0.376, 0.894, 0.233, 0.601, 0.145, 0.468,
];
/// Paired measurements (n = 12), also used for Pearson.
const X: [f64; 12] = [
    1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30, 2.01, 1.72, 2.27,
];
#[allow(clippy::approx_constant)] // 3.14 is a measurement, not π
const Y: [f64; 12] = [
    0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29, 1.45, 1.21, 1.86,
];
/// Equal n = 10, strongly negatively correlated, difference not significant at 5 %.
const U: [f64; 10] = [3.1, 4.7, 2.2, 5.9, 6.3, 1.8, 4.0, 7.5, 5.1, 2.9];
const V: [f64; 10] = [8.2, 6.1, 9.0, 4.4, 3.9, 9.7, 6.6, 2.5, 5.0, 7.7];

#[track_caller]
fn check_close(what: &str, got: f64, want: f64) {
    let scale = want.abs().max(f64::MIN_POSITIVE);
    assert!(
        (got - want).abs() <= REL * scale,
        "{what}: got {got:.17e}, want {want:.17e} (rel err {:.2e})",
        (got - want).abs() / scale
    );
}

#[track_caller]
fn check_all(what: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        check_close(&format!("{what}[{i}]"), *g, *w);
    }
}

/// Expected t-test numbers: t, df, p, 99 % CI and 95 % CI.
struct Want {
    t: f64,
    df: f64,
    p: f64,
    ci99: (f64, f64),
    ci95: (f64, f64),
}

/// `student_t`, `welch_t` or `paired_t`.
type TestFn = fn(&[f64], &[f64], f64) -> Result<TTest, StatsError>;

#[track_caller]
fn check_ttest(test: TestFn, a: &[f64], b: &[f64], want: Want) -> TTest {
    let res = test(a, b, DEFAULT_LEVEL).expect("valid data");
    check_close("t", res.t, want.t);
    check_close("df", res.df, want.df);
    check_close("p", res.p_two_sided, want.p);
    check_close("ci99 low", res.ci_low, want.ci99.0);
    check_close("ci99 high", res.ci_high, want.ci99.1);
    check_close(
        "mean_diff",
        res.mean_diff,
        (want.ci99.0 + want.ci99.1) / 2.0,
    );
    assert_eq!(res.level, DEFAULT_LEVEL);
    let res95 = test(a, b, 0.95).expect("valid data");
    check_close("ci95 low", res95.ci_low, want.ci95.0);
    check_close("ci95 high", res95.ci_high, want.ci95.1);
    assert_eq!(res95.t, res.t, "the level changes only the interval");
    res
}

#[test]
fn describe_matches_numpy() {
    // numpy: a.mean(), a.std(ddof=1), a.min(), a.max(); scipy.stats.sem(a)
    let s = describe(&A).expect("valid data");
    assert_eq!(s.n, 10);
    check_close("mean A", s.mean, 0.21610000000000001);
    check_close("std A", s.std, 0.11425551287453145);
    check_close("sem A", s.sem, 0.03613076559142114);
    assert_eq!((s.min, s.max), (0.054, 0.412));
    let s = describe(&B).expect("valid data");
    assert_eq!(s.n, 13);
    check_close("mean B", s.mean, 0.42084615384615376);
    check_close("std B", s.std, 0.25487410165081054);
    check_close("sem B", s.sem, 0.0706893570992168);
    assert_eq!((s.min, s.max), (0.049, 0.894));
}

#[test]
fn summary_formats_as_mean_plus_minus_std() {
    let s = describe(&A).expect("valid data");
    assert_eq!(s.to_string(), "0.216 ± 0.114");
    assert_eq!(format!("{s:.2}"), "0.22 ± 0.11");
    assert_eq!(s.mean_std(4), "0.2161 ± 0.1143");
    assert_eq!(s.mean_std(0), "0 ± 0");
}

#[test]
fn student_matches_scipy_unequal_n() {
    // scipy: res = stats.ttest_ind(A, B, equal_var=True); res.statistic, res.df, res.pvalue,
    // res.confidence_interval(0.99), res.confidence_interval(0.95)
    let res = check_ttest(
        student_t,
        &A,
        &B,
        Want {
            t: -2.3552251783456377,
            df: 21.0,
            p: 0.02831375094461307,
            ci99: (-0.4508839690286351, 0.0413916613363276),
            ci95: (-0.3855326621206157, -0.02395964557169178),
        },
    );
    assert_eq!(res.kind, TestKind::Student);
    assert_eq!((res.n_a, res.n_b), (10, 13));
    // Significant at 5 % but not at the seeds' 1 %; the 99 % CI straddles 0, the 95 % does not.
    assert!(!res.significant(0.01));
    assert!(res.significant(0.05));
}

#[test]
fn student_matches_scipy_equal_n() {
    // scipy: stats.ttest_ind(U, V, equal_var=True), as above
    check_ttest(
        student_t,
        &U,
        &V,
        Want {
            t: -2.0562205969441565,
            df: 18.0,
            p: 0.05455760153142248,
            ci99: (-4.703744195030499, 0.7837441950304966),
            ci95: (-3.9626096446033565, 0.04260964460335481),
        },
    );
}

#[test]
fn welch_matches_scipy_unequal_n_and_variance() {
    // scipy: stats.ttest_ind(A, B, equal_var=False); .df is the Welch–Satterthwaite df
    let res = check_ttest(
        welch_t,
        &A,
        &B,
        Want {
            t: -2.5790643008528775,
            df: 17.49667567238111,
            p: 0.01920205001599664,
            ci99: (-0.434025065779298, 0.024532758086990514),
            ci95: (-0.3718782423264886, -0.037614065365818905),
        },
    );
    assert_eq!(res.kind, TestKind::Welch);
    // Effect sizes use the pooled SD and df = n_a + n_b − 2 for Welch too.
    let student = student_t(&A, &B, DEFAULT_LEVEL).expect("valid data");
    assert_eq!(
        (res.cohens_d, res.hedges_g),
        (student.cohens_d, student.hedges_g)
    );
}

#[test]
fn paired_matches_scipy() {
    // scipy: stats.ttest_rel(X, Y), res.confidence_interval(0.99) / (0.95)
    let res = check_ttest(
        paired_t,
        &X,
        &Y,
        Want {
            t: 4.22696415858892,
            df: 11.0,
            p: 0.0014196474760900027,
            ci99: (0.11862834342587508, 0.7758716565741248),
            ci95: (0.214366404133504, 0.680133595866496),
        },
    );
    assert_eq!(res.kind, TestKind::Paired);
    assert_eq!((res.n_a, res.n_b), (12, 12));
    assert!(res.significant(1.0 - DEFAULT_LEVEL));
}

#[test]
fn swapping_samples_negates_t_and_interval() {
    for test in [student_t, welch_t, paired_t] {
        let ab = test(&U, &V, DEFAULT_LEVEL).expect("valid data");
        let ba = test(&V, &U, DEFAULT_LEVEL).expect("valid data");
        check_close("t", ba.t, -ab.t);
        check_close("p", ba.p_two_sided, ab.p_two_sided);
        check_close("ci low", ba.ci_low, -ab.ci_high);
        check_close("ci high", ba.ci_high, -ab.ci_low);
        check_close("d", ba.cohens_d, -ab.cohens_d);
    }
}

#[test]
fn effect_sizes_match_hand_formulas() {
    // numpy + scipy.special, by hand:
    //   sp = sqrt(((na-1)*a.var(ddof=1) + (nb-1)*b.var(ddof=1)) / (na+nb-2))
    //   d = (a.mean() - b.mean()) / sp
    //   J(df) = gamma(df/2) / (sqrt(df/2) * gamma((df-1)/2)); g = d * J(na+nb-2)
    let res = student_t(&A, &B, DEFAULT_LEVEL).expect("valid data");
    check_close("cohen d A,B", res.cohens_d, -0.9906601130109176);
    check_close("hedges g A,B", res.hedges_g, -0.9547806349657545);
    // Paired, by hand: dd = X - Y; d_z = dd.mean() / dd.std(ddof=1); g = d_z * J(n-1)
    let res = paired_t(&X, &Y, DEFAULT_LEVEL).expect("valid data");
    check_close("d_z X,Y", res.cohens_d, 1.2202194474081065);
    check_close("hedges g X,Y", res.hedges_g, 1.1347550454403923);
}

#[test]
fn hedges_correction_matches_exact_gamma_ratio() {
    // mpmath 1.4.1 at 40 digits, repr(float(..)): gamma(df/2) / (sqrt(df/2) * gamma((df-1)/2))
    let cases = [
        (2.0, 0.5641895835477563),
        (3.0, 0.7236012545582676),
        (11.0, 0.9299598099757785),
        (21.0, 0.963782252284172),
        (99.0, 0.9924018511144228),
        (100.0, 0.9924780549814448),
        (1000.0, 0.9992497811797164),
        (250.0, 0.9969964955074352),
        (12345.0, 0.9999392452231523),
        (1e5, 0.9999924999781249),
        (1e7, 0.9999999249999978),
    ];
    for (df, want) in cases {
        check_close(&format!("J({df})"), hedges_correction(df), want);
    }
    assert_eq!(hedges_correction(1.0), 0.0);
    // The usual approximation 1 − 3/(4ν − 1) is close but not what we compute.
    let approx = 1.0 - 3.0 / (4.0 * 21.0 - 1.0);
    assert!((hedges_correction(21.0) - approx).abs() > 1e-5);
}

#[test]
fn holm_matches_statsmodels() {
    // statsmodels: multipletests(p, method='holm')[1]; ties at 0.04, saturation at 1
    let p = [0.01, 0.04, 0.03, 0.005, 0.04, 0.4, 0.6, 0.001, 0.45];
    let want = [
        0.07,
        0.2,
        0.18,
        0.04,
        0.2,
        1.0,
        1.0,
        0.009000000000000001,
        1.0,
    ];
    check_all("holm", &holm(&p).expect("valid p"), &want);
    // multipletests([1.0, 0.0, 0.5, 0.5], method='holm')[1]
    let got = holm(&[1.0, 0.0, 0.5, 0.5]).expect("valid p");
    assert_eq!(got, [1.0, 0.0, 1.0, 1.0]);
}

#[test]
fn benjamini_hochberg_matches_statsmodels() {
    // statsmodels: multipletests(p, method='fdr_bh')[1]
    let p = [0.01, 0.04, 0.03, 0.005, 0.04, 0.4, 0.6, 0.001, 0.45];
    let want = [
        0.030000000000000002,
        0.060000000000000005,
        0.060000000000000005,
        0.022500000000000003,
        0.060000000000000005,
        0.5062500000000001,
        0.6,
        0.009000000000000001,
        0.5062500000000001,
    ];
    check_all("bh", &benjamini_hochberg(&p).expect("valid p"), &want);
    // multipletests([1.0, 0.0, 0.5, 0.5], method='fdr_bh')[1]
    let got = benjamini_hochberg(&[1.0, 0.0, 0.5, 0.5]).expect("valid p");
    check_all(
        "bh small",
        &got,
        &[1.0, 0.0, 0.6666666666666666, 0.6666666666666666],
    );
}

#[test]
fn corrections_of_nothing_and_of_one() {
    assert_eq!(holm(&[]), Ok(vec![]));
    assert_eq!(benjamini_hochberg(&[]), Ok(vec![]));
    assert_eq!(holm(&[0.03]), Ok(vec![0.03]));
    assert_eq!(benjamini_hochberg(&[0.03]), Ok(vec![0.03]));
}

#[test]
fn pearson_matches_scipy() {
    // scipy: res = stats.pearsonr(x, y); res.statistic, res.pvalue,
    // res.confidence_interval(0.95) and (0.99) (Fisher z); t by hand r*sqrt((n-2)/(1-r*r))
    let c = pearson(&X, &Y, 0.95).expect("valid data");
    assert_eq!(c.n, 12);
    check_close("r X,Y", c.r, 0.8542763640678541);
    check_close("t X,Y", c.t, 5.196921537409997);
    check_close("p X,Y", c.p_two_sided, 0.0004030861934595535);
    check_close("ci95 low", c.ci_low, 0.5500462397266901);
    check_close("ci95 high", c.ci_high, 0.9583346768113596);
    let c = pearson(&X, &Y, DEFAULT_LEVEL).expect("valid data");
    check_close("ci99 low", c.ci_low, 0.39115179963509655);
    check_close("ci99 high", c.ci_high, 0.9721695128395078);

    let c = pearson(&U, &V, 0.95).expect("valid data");
    check_close("r U,V", c.r, -0.994422077329197);
    check_close("t U,V", c.t, -26.666804069905456);
    check_close("p U,V", c.p_two_sided, 4.206860242880959e-09);
    check_close("ci95 low", c.ci_low, -0.9987295383455529);
    check_close("ci95 high", c.ci_high, -0.9756879459962612);
    let c = pearson(&U, &V, DEFAULT_LEVEL).expect("valid data");
    check_close("ci99 low", c.ci_low, -0.9992022289377201);
    check_close("ci99 high", c.ci_high, -0.9615506669219601);
}

#[test]
fn pearson_of_a_perfect_line() {
    let x = [1.0, 2.0, 3.0, 4.0, 5.0];
    let y: Vec<f64> = x.iter().map(|v| 7.0 - 2.0 * v).collect();
    let c = pearson(&x, &y, DEFAULT_LEVEL).expect("valid data");
    assert_eq!((c.r, c.t, c.p_two_sided), (-1.0, f64::NEG_INFINITY, 0.0));
    assert_eq!((c.ci_low, c.ci_high), (-1.0, -1.0));
}

#[test]
fn too_few_samples() {
    assert_eq!(
        describe(&[1.0]),
        Err(StatsError::TooFewSamples {
            statistic: "describe",
            sample: "data",
            got: 1,
            need: 2
        })
    );
    assert_eq!(
        student_t(&A, &[0.3], DEFAULT_LEVEL),
        Err(StatsError::TooFewSamples {
            statistic: "Student t-test",
            sample: "b",
            got: 1,
            need: 2
        })
    );
    assert!(matches!(
        welch_t(&[], &B, DEFAULT_LEVEL),
        Err(StatsError::TooFewSamples {
            sample: "a",
            got: 0,
            need: 2,
            ..
        })
    ));
    assert!(matches!(
        paired_t(&[1.0], &[2.0], DEFAULT_LEVEL),
        Err(StatsError::TooFewSamples {
            got: 1,
            need: 2,
            ..
        })
    ));
    assert!(matches!(
        pearson(&X[..3], &Y[..3], DEFAULT_LEVEL),
        Err(StatsError::TooFewSamples {
            sample: "x",
            got: 3,
            need: 4,
            ..
        })
    ));
}

#[test]
fn length_mismatch() {
    assert_eq!(
        paired_t(&X, &Y[..11], DEFAULT_LEVEL),
        Err(StatsError::LengthMismatch {
            statistic: "paired t-test",
            len_a: 12,
            len_b: 11
        })
    );
    assert!(matches!(
        pearson(&A, &B, DEFAULT_LEVEL),
        Err(StatsError::LengthMismatch {
            len_a: 10,
            len_b: 13,
            ..
        })
    ));
}

#[test]
fn non_finite_input_names_the_index() {
    let mut bad = A;
    bad[4] = f64::NAN;
    assert!(matches!(
        describe(&bad),
        Err(StatsError::NonFinite {
            sample: "data",
            index: 4,
            ..
        })
    ));
    assert!(matches!(
        student_t(&A, &bad, DEFAULT_LEVEL),
        Err(StatsError::NonFinite {
            sample: "b",
            index: 4,
            ..
        })
    ));
    bad[4] = f64::INFINITY;
    assert!(matches!(
        welch_t(&bad, &B, DEFAULT_LEVEL),
        Err(StatsError::NonFinite {
            sample: "a",
            index: 4,
            ..
        })
    ));
    assert!(matches!(
        paired_t(&A, &bad, DEFAULT_LEVEL),
        Err(StatsError::NonFinite {
            sample: "b",
            index: 4,
            ..
        })
    ));
    assert!(matches!(
        pearson(&A, &bad, DEFAULT_LEVEL),
        Err(StatsError::NonFinite {
            sample: "y",
            index: 4,
            ..
        })
    ));
    assert_eq!(
        holm(&[0.1, f64::NAN]).map_err(|e| e.to_string()),
        Err("p-value `p[1]` = NaN is not in [0, 1]".to_string())
    );
    assert!(matches!(
        benjamini_hochberg(&[0.1, 1.5]),
        Err(StatsError::InvalidPValue {
            index: 1,
            value: 1.5
        })
    ));
    assert!(matches!(
        holm(&[-0.0, -1e-300]),
        Err(StatsError::InvalidPValue { index: 1, .. })
    ));
}

#[test]
fn zero_variance_is_an_error_where_t_is_undefined() {
    let flat = [2.0; 5];
    assert_eq!(
        student_t(&flat, &[3.0; 4], DEFAULT_LEVEL),
        Err(StatsError::ZeroVariance {
            statistic: "Student t-test",
            sample: "a and b"
        })
    );
    assert!(matches!(
        welch_t(&flat, &flat, DEFAULT_LEVEL),
        Err(StatsError::ZeroVariance { .. })
    ));
    // Differences constant (b = a − 1): d = 1 everywhere.
    let shifted: Vec<f64> = X.iter().map(|x| x - 1.0).collect();
    assert!(matches!(
        paired_t(&X, &shifted, DEFAULT_LEVEL),
        Err(StatsError::ZeroVariance {
            sample: "a − b",
            ..
        })
    ));
    assert!(matches!(
        pearson(&[1.0, 2.0, 3.0, 4.0], &[5.0; 4], DEFAULT_LEVEL),
        Err(StatsError::ZeroVariance { sample: "y", .. })
    ));
    // One flat sample is fine: the other supplies the variance.
    let res = welch_t(&flat, &A, DEFAULT_LEVEL).expect("A varies");
    check_close("welch df with one flat sample", res.df, 9.0);
    // A flat sample still has a summary.
    assert_eq!(describe(&flat).map(|s| s.std), Ok(0.0));
}

#[test]
fn level_must_lie_strictly_between_0_and_1() {
    for level in [0.0, 1.0, 99.0, -0.5, f64::NAN] {
        assert!(matches!(
            student_t(&A, &B, level),
            Err(StatsError::InvalidLevel { .. })
        ));
        assert!(matches!(
            pearson(&X, &Y, level),
            Err(StatsError::InvalidLevel { .. })
        ));
    }
}

#[test]
fn overflowing_data_is_an_error_not_a_panic() {
    let huge = [1e300, -1e300, 1e300];
    assert!(matches!(describe(&huge), Err(StatsError::Overflow { .. })));
    assert!(matches!(
        student_t(&huge, &A, DEFAULT_LEVEL),
        Err(StatsError::Overflow { .. })
    ));
    assert!(matches!(
        welch_t(&huge, &A, DEFAULT_LEVEL),
        Err(StatsError::Overflow { .. })
    ));
    assert!(matches!(
        paired_t(&huge, &A[..3], DEFAULT_LEVEL),
        Err(StatsError::Overflow { .. })
    ));
    let x = [1e300, -1e300, 1e300, 0.0];
    assert!(matches!(
        pearson(&x, &A[..4], DEFAULT_LEVEL),
        Err(StatsError::Overflow { .. })
    ));
}

#[test]
fn results_serialise_for_tables() {
    let res = student_t(&A, &B, DEFAULT_LEVEL).expect("valid data");
    let json = serde_json::to_value(&res).expect("serialisable");
    assert_eq!(json["kind"], "Student");
    assert_eq!(json["df"], 21.0);
    assert_eq!(json["n_b"], 13);
    let json = serde_json::to_value(describe(&A).expect("valid data")).expect("serialisable");
    assert_eq!(json["n"], 10);
}

#[test]
fn median_of_odd_even_empty_and_non_finite() {
    assert_eq!(median(vec![]), None);
    assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
    assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), Some(2.5));
    assert_eq!(median(vec![f64::NAN, 5.0, f64::INFINITY]), Some(5.0));
    assert_eq!(median(vec![f64::NAN]), None);
}

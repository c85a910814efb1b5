//! Schemas read back from hand-made output folders: columns in file order with polars dtypes,
//! families by pattern, disagreements, the cache's files; the page rendered, read back, and a
//! renamed column in it caught.

use std::path::Path;

use polars::prelude::{DataFrame, df};

use super::doc::{self, Documented};
use super::*;
use crate::report::Provenance;
use crate::report::table::parquet_bytes;

fn put(path: &Path, df: &DataFrame) {
    std::fs::create_dir_all(path.parent().expect("parent")).expect("mkdir");
    std::fs::write(
        path,
        parquet_bytes(df, &Provenance::default()).expect("parquet"),
    )
    .expect("write");
}

const DOCS: &[TableDoc] = &[
    table("scans", "One scan."),
    table("snap_{n}", "One snapshot's pixels."),
    table("snap_boxes", "The snapshots' boxes."),
    table("obs_{name}", "One camera's observations."),
];

/// Two sessions of dataset `lab`; `scans` of `b` has its columns in another order.
fn output(dir: &Path, disagree: bool) {
    let s = dir.join("p/sessions/dataset=lab");
    let scans =
        df!("idx" => [0i64, 1], "range_m" => [1.0, 2.0], "ok" => [true, false]).expect("df");
    put(&s.join("session=a/scans.parquet"), &scans);
    let other = if disagree {
        df!("range_m" => [1.0], "idx" => [0i64], "ok" => [true]).expect("df")
    } else {
        scans.clone()
    };
    put(&s.join("session=b/scans.parquet"), &other);
    let snap = df!("x" => [1i32], "name" => ["s"]).expect("df");
    put(&s.join("session=a/snap_0.parquet"), &snap);
    put(&s.join("session=a/snap_12.parquet"), &snap);
    put(
        &s.join("session=a/snap_boxes.parquet"),
        &df!("n" => [2i64]).expect("df"),
    );
    put(
        &s.join("session=b/obs_cam_1.parquet"),
        &df!("t" => [0.5]).expect("df"),
    );
    std::fs::write(s.join("session=a/key.txt"), "k").expect("key");
    std::fs::write(s.join("session=b/key.txt"), "k").expect("key");
    std::fs::write(s.join("session=b/source.txt"), "h\np\n").expect("source");
    std::fs::create_dir_all(dir.join("p/sessions/lab/old")).expect("old layout");
    let t = dir.join("p/tables");
    put(
        &t.join("results.parquet"),
        &df!("session" => ["a"], "mota" => [0.5]).expect("df"),
    );
    std::fs::write(
        t.join("results.md"),
        "**Results per session**\n\n| session |\n",
    )
    .expect("md");
    put(
        &t.join("results.samples.parquet"),
        &df!("err_m" => [0.1]).expect("df"),
    );
}

fn cols(t: &TableSchema) -> Vec<(&str, &str)> {
    t.columns()
        .iter()
        .map(|c| (c.name.as_str(), c.dtype.as_str()))
        .collect()
}

#[test]
fn placeholders_match_digits_or_anything() {
    assert!(matches("snap_{n}", "snap_0") && matches("snap_{n}", "snap_12"));
    assert!(!matches("snap_{n}", "snap_boxes") && !matches("snap_{n}", "snap_"));
    assert!(matches("obs_{name}", "obs_cam_1") && !matches("obs_{name}", "obs_"));
    assert!(matches("scans", "scans") && !matches("scans", "scans2"));
    assert!(matches("{name}_x", "a_x") && !matches("{name}_x", "a_y"));
}

#[test]
fn tables_are_read_in_file_order_and_grouped_by_pattern() {
    let dir = tempfile::tempdir().expect("tempdir");
    output(dir.path(), false);
    let p = read_pipeline(dir.path(), "p", DOCS).expect("reads");
    assert_eq!(p.sessions, 2);
    let names: Vec<&str> = p.session_tables.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["obs_{name}", "scans", "snap_boxes", "snap_{n}"]);
    let scans = &p.session_tables[1];
    assert_eq!(
        cols(scans),
        [("idx", "i64"), ("range_m", "f64"), ("ok", "bool")]
    );
    assert_eq!((scans.files(), scans.variants.len()), (2, 1));
    assert_eq!(scans.meaning.as_deref(), Some("One scan."));
    assert!(scans.columns().iter().all(|c| c.nullable));
    assert_eq!(cols(&p.session_tables[3]), [("x", "i32"), ("name", "str")]);
    // two snapshots of one session: one family, in one of the two sessions
    assert_eq!(
        (p.session_tables[3].files(), p.session_tables[3].folders),
        (2, 1)
    );
    let counts: Vec<(&str, usize)> = p
        .cache_files
        .iter()
        .map(|(f, n)| (f.as_str(), *n))
        .collect();
    assert_eq!(counts, [("key.txt", 2), ("source.txt", 1)]);
    assert_eq!(p.ignored, [dir.path().join("p/sessions/lab")]);
    let agg: Vec<(&str, Option<&str>)> = p
        .aggregate_tables
        .iter()
        .map(|t| (t.name.as_str(), t.meaning.as_deref()))
        .collect();
    assert_eq!(
        agg,
        [
            ("results", Some("Results per session.")),
            (
                "results.samples",
                Some("The per-sample values behind `results` (Results per session).")
            )
        ]
    );
    assert!(p.disagreements().is_empty());
    assert!(doc::problems(&p).is_empty(), "{:?}", doc::problems(&p));
}

#[test]
fn sessions_that_disagree_and_undescribed_tables_are_problems() {
    let dir = tempfile::tempdir().expect("tempdir");
    output(dir.path(), true);
    std::fs::write(
        dir.path()
            .join("p/sessions/dataset=lab/session=a/notes.txt"),
        "",
    )
    .expect("notes");
    let p = read_pipeline(dir.path(), "p", &DOCS[1..]).expect("reads");
    let d = p.disagreements();
    assert_eq!(d.len(), 1);
    assert_eq!(d[0].1.name, "scans");
    let problems = doc::problems(&p);
    assert_eq!(problems.len(), 3, "{problems:#?}");
    assert!(problems[0].starts_with("p: the per-session table `scans` has 2 different schemas"));
    assert!(problems[1].contains("`scans`") && problems[1].contains("no meaning in code"));
    assert!(problems[2].contains("`notes.txt`"));
}

#[test]
fn an_absent_pipeline_is_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let e = read_pipeline(dir.path(), "nope", DOCS).expect_err("absent");
    assert!(e.to_string().contains("no output of pipeline nope"), "{e}");
}

#[test]
fn the_page_reads_back_and_a_renamed_column_fails_the_check() {
    let dir = tempfile::tempdir().expect("tempdir");
    output(dir.path(), false);
    let p = read_pipeline(dir.path(), "p", DOCS).expect("reads");
    let info = KindInfo {
        version: 7,
        session_tables: DOCS,
    };
    let page = doc::render(&[Documented {
        file: Path::new("pipelines/p.toml"),
        kind: "k",
        info,
        schemas: &p,
    }]);
    assert!(
        page.contains("`pipelines/p.toml` (kind `k`, VERSION 7)"),
        "{page}"
    );
    assert!(page.contains("#### `obs_{name}`\n\nOne camera's observations. (in 1 of 2 sessions)"));
    assert!(page.contains("#### `snap_{n}`\n\nOne snapshot's pixels. (in 1 of 2 sessions)"));
    assert!(page.contains("| `range_m` | f64 |\n| `ok` | bool |"));
    let sections = doc::parse(&page);
    let s = &sections["p"];
    assert_eq!(
        s.session_tables["scans"],
        [("idx", "i64"), ("range_m", "f64"), ("ok", "bool")].map(|(a, b)| (a.into(), b.into()))
    );
    assert_eq!(
        s.aggregate_tables.keys().collect::<Vec<_>>(),
        ["results", "results.samples"]
    );
    assert!(doc::check(&p, &sections).is_empty());

    let renamed = page.replace("| `range_m` | f64 |", "| `range` | f64 |");
    let problems = doc::check(&p, &doc::parse(&renamed));
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(
        problems[0].starts_with(
            "p: the per-session table `scans` differs from the page: column 2 is `range` (f64) \
             in the page, `range_m` (f64) in the run"
        ),
        "{}",
        problems[0]
    );
    let retyped = page.replace("| `mota` | f64 |", "| `mota` | i64 |");
    assert_eq!(doc::check(&p, &doc::parse(&retyped)).len(), 1);
    let dropped = page.replace("#### `snap_boxes`", "#### `snap_box`");
    let problems = doc::check(&p, &doc::parse(&dropped));
    assert!(problems[0].contains("`snap_boxes`") && problems[0].contains("not in the page"));
    let other = page.replace("## Pipeline `p`", "## Pipeline `q`");
    assert!(doc::check(&p, &doc::parse(&other))[0].contains("has no section"));
}

/// The files a real store leaves in a session folder are the ones `CACHE_FILES` describes.
#[test]
fn the_cache_writes_only_the_files_the_page_describes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path();
    let folder = out.join("p/sessions/dataset=d/session=s");
    let mut tables = crate::run::SessionTables::new();
    tables.insert("t".into(), df!("a" => [1i64]).expect("df"));
    let warnings = vec!["a warning".to_string()];
    crate::run::cache::store(
        out,
        &folder,
        "key",
        (Path::new("d/s.mcap"), 7),
        (&tables, &warnings),
        &Provenance::default(),
    )
    .expect("stores");
    let p = read_pipeline(out, "p", &[table("t", "A row.")]).expect("reads");
    let files: Vec<&str> = p.cache_files.keys().map(String::as_str).collect();
    let known: Vec<&str> = CACHE_FILES.iter().map(|(f, _)| *f).collect();
    assert_eq!(files, known);
    assert!(doc::problems(&p).is_empty());
}

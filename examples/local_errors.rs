//! Error analysis of the s003 local tracks: classifies every miss and false positive of the
//! `local_tracks` scoring by its likely cause, from the cached per-session tables
//! (`tracks.parquet`, `gt_boxes.parquet` under `out/s003_zivkovic_background/sessions/`).
//!
//! Usage: local_errors SESSION_DIR... [--min-iou 0.5] [--phases FROM:TO:NAME,...] [--dump FROM TO]
//!
//! `--phases` prefixes each cause with the phase (frames FROM..TO) it falls in; `--dump`
//! prints the boxes of frames FROM..=TO (`c`: colour-tracked).
//!
//! Per frame, tracks and ground-truth boxes are matched greedily by IoU (highest first, IoU ≥
//! `--min-iou`): close to CLEAR MOT's counts, which also keep the previous frame's matches.
//! A miss is then (by the best-overlapping track `t` of the person's box `g`):
//! - `no track near`: no track with IoU ≥ 0.1 (sub-counted: in the first 30 frames, box under
//!   1,000 px², visibility < 0.7);
//! - `fragment`: `t` lies inside `g` (≥ 80 % of `t`) but covers less than half of `g`
//!   (`split`: two or more tracks inside `g`);
//! - `merged`: `g` lies inside `t` and `t` holds ≥ 30 % of another person's box too;
//! - `inflated`: `g` lies inside `t`, no other person (a shadow, a halo, a long colour region);
//! - `offset`: neither (a shifted box: a lagging or drifting colour region);
//! - `taken`: the best track (IoU ≥ 0.5) went to another person.
//!
//! A false positive (by the best-overlapping person `g` of the track's box `t`):
//! `background` (no person box holds 20 % of `t`), `fragment` (`t` inside `g`), `merged` /
//! `inflated` (`g` inside `t`), `offset`; each split by the track's mode (blob / colour).

use std::collections::BTreeMap;
use std::fs::File;
use std::path::Path;

use peopletrack::report::columns;
use polars::prelude::*;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

#[derive(Clone, Copy)]
struct Bx {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

impl Bx {
    fn area(&self) -> f64 {
        (self.x1 - self.x0).max(0.0) * (self.y1 - self.y0).max(0.0)
    }
    fn inter(&self, o: &Bx) -> f64 {
        let w = (self.x1.min(o.x1) - self.x0.max(o.x0)).max(0.0);
        let h = (self.y1.min(o.y1) - self.y0.max(o.y0)).max(0.0);
        w * h
    }
    fn iou(&self, o: &Bx) -> f64 {
        let i = self.inter(o);
        let u = self.area() + o.area() - i;
        if u > 0.0 { i / u } else { 0.0 }
    }
}

struct Trk {
    b: Bx,
    colour: bool,
}

struct Gt {
    b: Bx,
    vis: f64,
}

fn f64s(df: &DataFrame, c: &str) -> Res<Vec<f64>> {
    Ok(columns::f64s(df, c)?)
}

fn read(p: &Path) -> Res<DataFrame> {
    Ok(ParquetReader::new(File::open(p)?).finish()?)
}

#[derive(Default)]
struct Counts(BTreeMap<String, u64>);

impl Counts {
    fn add(&mut self, k: impl Into<String>) {
        *self.0.entry(k.into()).or_default() += 1;
    }
}

fn main() -> Res<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut min_iou = 0.5;
    if let Some(i) = args.iter().position(|a| a == "--min-iou") {
        min_iou = args.get(i + 1).ok_or("--min-iou needs a value")?.parse()?;
        args.drain(i..i + 2);
    }
    let mut dump: Option<(i64, i64)> = None;
    if let Some(i) = args.iter().position(|a| a == "--dump") {
        let a: i64 = args.get(i + 1).ok_or("--dump needs FROM TO")?.parse()?;
        let b: i64 = args.get(i + 2).ok_or("--dump needs FROM TO")?.parse()?;
        dump = Some((a, b));
        args.drain(i..i + 3);
    }
    let mut phases: Vec<(i64, i64, String)> = Vec::new();
    if let Some(i) = args.iter().position(|a| a == "--phases") {
        for ph in args
            .get(i + 1)
            .ok_or("--phases needs FROM:TO:NAME,...")?
            .split(',')
        {
            let v: Vec<&str> = ph.split(':').collect();
            if v.len() != 3 {
                return Err(format!("bad phase {ph:?}, want FROM:TO:NAME").into());
            }
            phases.push((v[0].parse()?, v[1].parse()?, v[2].to_string()));
        }
        args.drain(i..i + 2);
    }
    if args.is_empty() {
        return Err("usage: local_errors SESSION_DIR... [--min-iou 0.5]".into());
    }
    for dir in &args {
        let dir = Path::new(dir);
        let t = read(&dir.join("tracks.parquet"))?;
        let g = read(&dir.join("gt_boxes.parquet"))?;
        let mut frames: BTreeMap<i64, (Vec<Trk>, Vec<Gt>)> = BTreeMap::new();
        let tf = f64s(&t, "frame")?;
        let modes: Vec<String> = t
            .column("mode")?
            .str()?
            .iter()
            .map(|s| s.unwrap_or("").to_string())
            .collect();
        let (tx0, ty0, tx1, ty1) = (
            f64s(&t, "x0")?,
            f64s(&t, "y0")?,
            f64s(&t, "x1")?,
            f64s(&t, "y1")?,
        );
        for i in 0..tf.len() {
            frames.entry(tf[i] as i64).or_default().0.push(Trk {
                b: Bx {
                    x0: tx0[i],
                    y0: ty0[i],
                    x1: tx1[i],
                    y1: ty1[i],
                },
                colour: modes[i] != "blob",
            });
        }
        let gf = f64s(&g, "frame")?;
        let (gx0, gy0, gx1, gy1, gv) = (
            f64s(&g, "x0")?,
            f64s(&g, "y0")?,
            f64s(&g, "x1")?,
            f64s(&g, "y1")?,
            f64s(&g, "visibility")?,
        );
        for i in 0..gf.len() {
            frames.entry(gf[i] as i64).or_default().1.push(Gt {
                b: Bx {
                    x0: gx0[i],
                    y0: gy0[i],
                    x1: gx1[i],
                    y1: gy1[i],
                },
                vis: gv[i],
            });
        }
        let (mut misses, mut fps) = (Counts::default(), Counts::default());
        let (mut n_gt, mut n_tr, mut n_match) = (0u64, 0u64, 0u64);
        for (&frame, (trs, gts)) in &frames {
            if dump.is_some_and(|(a, b)| (a..=b).contains(&frame)) {
                let f = |b: &Bx| format!("[{:.0} {:.0} {:.0} {:.0}]", b.x0, b.y0, b.x1, b.y1);
                let g: Vec<String> = gts
                    .iter()
                    .map(|g| format!("{}v{:.2}", f(&g.b), g.vis))
                    .collect();
                let t: Vec<String> = trs
                    .iter()
                    .map(|t| format!("{}{}", f(&t.b), if t.colour { "c" } else { "" }))
                    .collect();
                println!("{frame}: gt {} | tr {}", g.join(" "), t.join(" "));
            }
            n_gt += gts.len() as u64;
            n_tr += trs.len() as u64;
            let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
            for (ti, tr) in trs.iter().enumerate() {
                for (gi, gt) in gts.iter().enumerate() {
                    let iou = tr.b.iou(&gt.b);
                    if iou >= min_iou {
                        pairs.push((iou, ti, gi));
                    }
                }
            }
            pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
            let (mut tm, mut gm) = (vec![false; trs.len()], vec![false; gts.len()]);
            for (_, ti, gi) in pairs {
                if !tm[ti] && !gm[gi] {
                    tm[ti] = true;
                    gm[gi] = true;
                    n_match += 1;
                }
            }
            for (gi, gt) in gts.iter().enumerate() {
                if gm[gi] {
                    continue;
                }
                let why = classify_miss(frame, gi, gt, gts, trs, min_iou);
                misses.add(with_phase(&phases, frame, why));
            }
            for (ti, tr) in trs.iter().enumerate() {
                if tm[ti] {
                    continue;
                }
                fps.add(with_phase(&phases, frame, classify_fp(tr, gts)));
            }
        }
        println!(
            "== {}: {} gt boxes, {} track boxes, {} matched (IoU ≥ {min_iou})",
            dir.display(),
            n_gt,
            n_tr,
            n_match
        );
        println!("  misses {}:", n_gt - n_match);
        for (k, v) in &misses.0 {
            println!("    {v:6}  {k}");
        }
        println!("  false positives {}:", n_tr - n_match);
        for (k, v) in &fps.0 {
            println!("    {v:6}  {k}");
        }
    }
    Ok(())
}

/// `why` prefixed with the name of the phase (`--phases`) holding `frame`, if any.
fn with_phase(phases: &[(i64, i64, String)], frame: i64, why: String) -> String {
    match phases.iter().find(|(a, b, _)| (*a..*b).contains(&frame)) {
        Some((_, _, name)) => format!("{name}: {why}"),
        None => why,
    }
}

fn mode(t: &Trk) -> &'static str {
    if t.colour { "colour" } else { "blob" }
}

fn classify_miss(frame: i64, gi: usize, gt: &Gt, gts: &[Gt], trs: &[Trk], min_iou: f64) -> String {
    let best = trs
        .iter()
        .map(|t| (t.b.iou(&gt.b), t))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    let Some((iou, t)) = best.filter(|(iou, _)| *iou >= 0.1) else {
        let mut why = Vec::new();
        if frame < 30 {
            why.push("first 30 frames");
        }
        if gt.b.area() < 1000.0 {
            why.push("box < 1000 px²");
        }
        if gt.vis < 0.7 {
            why.push("visibility < 0.7");
        }
        return format!("no track near [{}]", why.join(", "));
    };
    if iou >= min_iou {
        return format!("taken by another person ({})", mode(t));
    }
    let inside_g = t.b.inter(&gt.b) / t.b.area().max(1e-9);
    let covers_g = t.b.inter(&gt.b) / gt.b.area().max(1e-9);
    let vis = if gt.vis < 0.7 { ", vis < 0.7" } else { "" };
    if inside_g >= 0.8 && covers_g < 0.5 {
        let n_inside = trs
            .iter()
            .filter(|o| o.b.inter(&gt.b) / o.b.area().max(1e-9) >= 0.8)
            .count();
        let what = if n_inside >= 2 { "split" } else { "fragment" };
        return format!("{what} ({}{vis})", mode(t));
    }
    if covers_g >= 0.8 {
        let other = gts
            .iter()
            .enumerate()
            .any(|(oi, o)| oi != gi && t.b.inter(&o.b) >= 0.3 * o.b.area());
        let what = if other { "merged" } else { "inflated" };
        return format!("{what} ({}{vis})", mode(t));
    }
    format!("offset ({}{vis})", mode(t))
}

fn classify_fp(t: &Trk, gts: &[Gt]) -> String {
    let best = gts
        .iter()
        .map(|g| (t.b.inter(&g.b), g))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    let Some((inter, g)) = best.filter(|(i, _)| *i >= 0.2 * t.b.area()) else {
        return format!("background ({})", mode(t));
    };
    let inside_g = inter / t.b.area().max(1e-9);
    let covers_g = inter / g.b.area().max(1e-9);
    if inside_g >= 0.8 {
        return format!("fragment ({})", mode(t));
    }
    if covers_g >= 0.8 {
        let n = gts
            .iter()
            .filter(|o| t.b.inter(&o.b) >= 0.3 * o.b.area())
            .count();
        let what = if n >= 2 { "merged" } else { "inflated" };
        return format!("{what} ({})", mode(t));
    }
    format!("offset ({})", mode(t))
}

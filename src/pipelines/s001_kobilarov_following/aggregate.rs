//! The aggregation: every session's cached tables read back, then the products in order —
//! Table I and the `rst` events ([`super::table1`]), the replayed methods and their t-tests
//! ([`super::compare`]), method 1's loss rate ([`super::method1`]), the real log
//! ([`super::real`]) and the figures ([`super::figures`]).

use super::params::Params;
use super::tables::{self, LoopRow, Method1Row, RealRow, TrackRow, TruthRow};
use crate::run::{Aggregate, Products};

/// One session's cached rows.
pub struct SessionData {
    pub name: String,
    pub tracks: Vec<TrackRow>,
    pub truth: Vec<TruthRow>,
    pub closed_loop: Vec<LoopRow>,
    pub method1: Vec<Method1Row>,
    pub real: Vec<RealRow>,
}

impl SessionData {
    /// A real log (its rows are in `real` only).
    pub fn is_real(&self) -> bool {
        !self.real.is_empty()
    }

    /// One method's rows, in scan order.
    pub fn method<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a TrackRow> + 'a {
        self.tracks.iter().filter(move |r| r.method == name)
    }
}

/// Every session, in the runner's (sorted) order.
pub fn load(ctx: &Aggregate) -> anyhow::Result<Vec<SessionData>> {
    ctx.sessions
        .iter()
        .map(|(info, t)| {
            let name = info.name.clone();
            Ok(SessionData {
                tracks: tables::read(t, tables::TRACKS, &name)?,
                truth: tables::read(t, tables::TRUTH, &name)?,
                closed_loop: tables::read(t, tables::LOOP, &name)?,
                method1: tables::read(t, tables::METHOD1, &name)?,
                real: tables::read(t, tables::REAL, &name)?,
                name,
            })
        })
        .collect()
}

/// Every table and figure.
pub fn products(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
    let data = load(ctx)?;
    let synthetic: Vec<&SessionData> = data.iter().filter(|d| !d.is_real()).collect();
    let mut out = Products::default();
    out.tables.extend(super::table1::tables(&synthetic, p)?);
    out.tables.extend(super::compare::tables(&synthetic, p)?);
    let m1: Vec<Method1Row> = synthetic.iter().flat_map(|d| d.method1.iter().cloned()).collect();
    out.tables.push(super::figures::method1_table(&m1, p)?);
    out.tables.push(super::real::table(&data, p)?);
    out.figures.extend(super::figures::all(&synthetic, &m1, p));
    out.summary.extend(super::table1::summary(&synthetic, p));
    Ok(out)
}

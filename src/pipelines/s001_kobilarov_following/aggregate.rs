//! The aggregation: every session's cached tables read back, then the products in order —
//! Table I and the `rst` events ([`super::table1`]), the replayed methods and their t-tests
//! ([`super::compare`]), the colour separation and clutter density ([`super::colour`]), the
//! first losses ([`super::losses`]), method 1's loss rate
//! ([`super::method1`]), the real log ([`super::real`]) and the figures ([`super::figures`]).

use super::params::Params;
use super::tables::{Method1Row, SessionData, load};
use crate::run::{Aggregate, Products};

/// Every table and figure.
pub fn products(ctx: &Aggregate, p: &Params) -> anyhow::Result<Products> {
    let data = load(ctx)?;
    let synthetic: Vec<&SessionData> = data.iter().filter(|d| !d.is_real()).collect();
    let mut out = Products::default();
    out.tables.extend(super::table1::tables(&synthetic, p)?);
    out.tables.extend(super::compare::tables(&synthetic, p)?);
    out.tables.push(super::colour::table(&synthetic, p)?);
    out.tables
        .push(super::colour::scatter_table(&synthetic, p)?);
    out.tables
        .push(super::colour::clutter_table(&synthetic, p)?);
    out.tables.push(super::losses::table(&synthetic, p)?);
    out.tables
        .push(super::losses::occlusion_table(&synthetic, p)?);
    let m1: Vec<Method1Row> = synthetic
        .iter()
        .flat_map(|d| d.method1.iter().cloned())
        .collect();
    out.tables.push(super::figures::method1_table(&m1, p)?);
    out.tables.push(super::real::table(&data, p)?);
    out.figures.extend(super::figures::all(&synthetic, &m1, p));
    out.summary.extend(super::table1::summary(&synthetic, p));
    Ok(out)
}

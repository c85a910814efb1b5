//! The 3-D search per run: combinations triangulated per frame, pruned frames, objects
//! promoted and discarded, summed over sessions.

use std::collections::BTreeMap;

use crate::pipelines::s004_mohedano_multicam::scored::{Key, Scored};
use crate::pipelines::s004_mohedano_multicam::tables::VariantRow;
use crate::report::Table;
use crate::report::rows::Rows;

mod rows {
    #![allow(non_snake_case)]
    crate::table_row! {
        /// One run, all sessions.
        #[derive(Debug, Clone, PartialEq)]
        pub(crate) struct SearchRow {
            pub detector: String,
            pub selection: String,
            pub N_app: i64,
            pub combinations_per_frame: f64,
            pub pruned_frames: i64,
            pub promoted: i64,
            pub discarded: i64,
        }
    }
}
pub(crate) use rows::SearchRow;

/// Per run: Σ combinations, Σ pruned, Σ promoted, Σ discarded, Σ frames.
type Sums = (i64, i64, i64, i64, i64);

/// Per run (sorted), the sums over sessions; `sessions`: each session's runs and frames.
pub(crate) fn rows<'a>(
    sessions: impl IntoIterator<Item = (&'a [VariantRow], i64)>,
) -> Vec<SearchRow> {
    let mut acc: BTreeMap<Key, Sums> = BTreeMap::new();
    for (variants, frames) in sessions {
        for v in variants {
            let e = acc
                .entry((v.detector.clone(), v.selection.clone(), v.n_app))
                .or_default();
            e.0 += v.combinations;
            e.1 += v.pruned_frames;
            e.2 += v.promoted;
            e.3 += v.discarded;
            e.4 += frames;
        }
    }
    acc.into_iter()
        .map(|((detector, selection, n), v)| SearchRow {
            detector,
            selection,
            N_app: n,
            combinations_per_frame: v.0 as f64 / v.4.max(1) as f64,
            pruned_frames: v.1,
            promoted: v.2,
            discarded: v.3,
        })
        .collect()
}

pub(super) fn table(s: &Scored) -> anyhow::Result<Table> {
    let rows = rows(
        s.data
            .iter()
            .map(|d| (d.variants.as_slice(), d.session.frames)),
    );
    Ok(Table::new(
        "search",
        "The 3-D search: combinations triangulated per frame, frames where the exhaustive search was pruned, objects promoted and discarded",
        SearchRow::frame(&rows)?,
    )
    .with_precision("combinations_per_frame", 1)
    .with_note("pruned_frames counts frames in which the exhaustive search over new combinations would have exceeded max_combinations and only pairwise-coherent combinations were tried."))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(n: i64, combinations: i64) -> VariantRow {
        VariantRow {
            detector: "templates".into(),
            selection: "E_c".into(),
            n_app: n,
            combinations,
            pruned_frames: 1,
            promoted: 2,
            discarded: 3,
        }
    }

    #[test]
    fn runs_are_summed_over_sessions_and_combinations_divided_by_all_their_frames() {
        let a = [v(5, 100), v(1, 10)];
        let b = [v(5, 50)];
        let r = rows([(&a[..], 10), (&b[..], 20)]);
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].N_app, r[0].combinations_per_frame), (1, 1.0));
        assert_eq!(
            r[1],
            SearchRow {
                detector: "templates".into(),
                selection: "E_c".into(),
                N_app: 5,
                combinations_per_frame: 5.0,
                pruned_frames: 2,
                promoted: 4,
                discarded: 6,
            }
        );
    }
}

use std::collections::BTreeSet;
use std::convert::Infallible;

use super::*;

fn session(dataset: &str, name: &str) -> SessionRef {
    SessionRef {
        dataset: dataset.into(),
        name: name.into(),
        path: PathBuf::from(format!("/logs/{dataset}/{name}.mcap")),
    }
}

/// Sessions with given content hashes.
fn sessions() -> Vec<(SessionRef, u128)> {
    vec![
        (session("lab", "a"), 40),
        (session("lab", "b"), 10),
        (session("park", "c"), 30),
        (session("park", "d"), 20),
        (session("park", "e"), 10), // the same bytes as lab/b
    ]
}

fn shard(list: &[(SessionRef, u128)], k: usize, n: usize) -> Vec<String> {
    let hash = |s: &SessionRef| -> Result<u128, Infallible> {
        Ok(list.iter().find(|(x, _)| x == s).expect("known").1)
    };
    let refs = list.iter().map(|(s, _)| s.clone()).collect();
    assign(refs, (k, n), hash)
        .expect("no error")
        .into_iter()
        .map(|s| format!("{}/{}", s.dataset, s.name))
        .collect()
}

#[test]
fn assignment_follows_the_content_hash_order() {
    // order by (hash, dataset, name): lab/b 10, park/e 10, park/d 20, park/c 30, lab/a 40
    let list = sessions();
    assert_eq!(
        shard(&list, 1, 2),
        ["lab/a", "lab/b", "park/d"].map(String::from)
    );
    assert_eq!(shard(&list, 2, 2), ["park/c", "park/e"].map(String::from));
    assert_eq!(shard(&list, 1, 3), ["lab/b", "park/c"].map(String::from));
    assert_eq!(shard(&list, 2, 3), ["lab/a", "park/e"].map(String::from));
    assert_eq!(shard(&list, 3, 3), ["park/d"].map(String::from));
}

#[test]
fn assignment_ignores_names_and_order_and_covers_every_session_once() {
    let list = sessions();
    let mut shuffled = list.clone();
    shuffled.reverse();
    shuffled.swap(0, 2);
    for n in 1..=6 {
        let mut all = BTreeSet::new();
        for k in 1..=n {
            let a = shard(&list, k, n);
            assert_eq!(
                a,
                shard(&shuffled, k, n),
                "shard {k}/{n} moved with the glob order"
            );
            for s in a {
                assert!(all.insert(s), "a session in two shards of {n}");
            }
        }
        assert_eq!(all.len(), list.len(), "{n} shards lost a session");
    }
    // renaming a folder does not move its sessions between shards
    let renamed: Vec<_> = list
        .iter()
        .map(|(s, h)| {
            let mut s = s.clone();
            s.path = PathBuf::from("/elsewhere").join(s.path.file_name().expect("name"));
            (s, *h)
        })
        .collect();
    assert_eq!(shard(&renamed, 1, 2), shard(&list, 1, 2));
}

#[test]
fn a_hash_error_stops_the_assignment() {
    let refs = vec![session("lab", "a")];
    let got = assign(refs, (1, 1), |_| Err::<u128, _>("unreadable"));
    assert_eq!(got, Err("unreadable"));
}

#[test]
fn records_name_each_shard_that_does_not_count() {
    let dir = tempfile::tempdir().expect("tempdir");
    let root = dir.path();
    let write = |k: usize, n: usize, config: &str| {
        let r = Record {
            shard: k,
            of: n,
            config: config.into(),
            sessions: vec![RecordedSession {
                dataset: "lab".into(),
                name: format!("s{k}"),
                path: PathBuf::from("/logs/lab/s.mcap"),
                skipped: None,
            }],
        };
        let p = record_path(root, k, n);
        std::fs::create_dir_all(p.parent().expect("folder")).expect("mkdir");
        std::fs::write(p, serde_json::to_string(&r).expect("json")).expect("write");
    };
    write(1, 4, "cfg");
    write(2, 4, "old");
    // shard 3 left nothing; shard 4's record is cut short
    std::fs::write(record_path(root, 4, 4), "{\"shard\": 4, \"of\"").expect("write");
    let (records, problems) = check_records(root, 4, "cfg");
    assert_eq!(records.len(), 1);
    assert_eq!(records[0].sessions[0].name, "s1");
    assert_eq!(problems.len(), 3, "{problems:#?}");
    assert!(problems[0].starts_with("shard 2/4 ran another configuration"));
    assert!(problems[1].starts_with("shard 3/4 did not finish (no record"));
    assert!(problems[2].starts_with("shard 4/4: its record"));
    assert!(problems[2].contains("damaged"));
    // a record of another shard count is not read for this one
    write(1, 2, "cfg");
    let (_, two) = check_records(root, 2, "cfg");
    assert_eq!(
        two,
        [format!(
            "shard 2/2 did not finish (no record {})",
            record_path(root, 2, 2).display()
        )]
    );
}

//! Bad messages skipped while reading frames: counted per topic, with the first error's text
//! (which names the file, the topic and the log time), never fatal.

use std::collections::BTreeMap;
use std::fmt;

/// What was skipped on one topic.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct TopicSkips {
    pub count: u64,
    /// The text of the first error met on this topic.
    pub first_error: String,
}

/// One topic's skips as a flat row, for a table.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SkipRow {
    pub topic: String,
    pub count: u64,
    pub first_error: String,
}

/// Messages skipped while reading, per topic, plus the first error overall (in reading order).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Skips {
    by_topic: BTreeMap<String, TopicSkips>,
    first: Option<String>,
}

impl Skips {
    pub fn new() -> Self {
        Self::default()
    }

    /// Count one skipped message on `topic`; the first error per topic (and overall) is kept.
    pub fn note(&mut self, topic: &str, error: impl fmt::Display) {
        let text = || error.to_string();
        match self.by_topic.get_mut(topic) {
            Some(t) => t.count += 1,
            None => {
                self.by_topic.insert(
                    topic.to_string(),
                    TopicSkips {
                        count: 1,
                        first_error: text(),
                    },
                );
            }
        }
        if self.first.is_none() {
            self.first = Some(text());
        }
    }

    /// Add `other`'s skips (read after this one's: this one's first error stays first).
    pub fn merge(&mut self, other: Skips) {
        for (topic, s) in other.by_topic {
            match self.by_topic.get_mut(&topic) {
                Some(t) => t.count += s.count,
                None => {
                    self.by_topic.insert(topic, s);
                }
            }
        }
        if self.first.is_none() {
            self.first = other.first;
        }
    }

    /// Messages skipped on `topic`.
    pub fn count(&self, topic: &str) -> u64 {
        self.by_topic.get(topic).map_or(0, |t| t.count)
    }

    /// Messages skipped on all topics.
    pub fn total(&self) -> u64 {
        self.by_topic.values().map(|t| t.count).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.by_topic.is_empty()
    }

    /// The first error met, whatever its topic.
    pub fn first_error(&self) -> Option<&str> {
        self.first.as_deref()
    }

    /// The first error met on `topic`.
    pub fn first_error_on(&self, topic: &str) -> Option<&str> {
        self.by_topic.get(topic).map(|t| t.first_error.as_str())
    }

    /// Per topic, sorted by topic name.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &TopicSkips)> {
        self.by_topic.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// One row per topic with skips, sorted by topic name.
    pub fn rows(&self) -> Vec<SkipRow> {
        self.iter()
            .map(|(topic, s)| SkipRow {
                topic: topic.to_string(),
                count: s.count,
                first_error: s.first_error.clone(),
            })
            .collect()
    }
}

impl fmt::Display for Skips {
    /// `none`, or e.g. `3 skipped (/a: 2, /b: 1); first: <error>`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return write!(f, "none");
        }
        let per: Vec<String> = self
            .iter()
            .map(|(t, s)| format!("{t}: {}", s.count))
            .collect();
        write!(f, "{} skipped ({})", self.total(), per.join(", "))?;
        if let Some(e) = &self.first {
            write!(f, "; first: {e}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_first_errors_and_merges() {
        let mut a = Skips::new();
        assert_eq!(a.to_string(), "none");
        a.note("/b", "b1");
        a.note("/a", "a1");
        a.note("/b", "b2");
        assert_eq!((a.count("/a"), a.count("/b"), a.total()), (1, 2, 3));
        assert_eq!(a.first_error(), Some("b1"));
        assert_eq!(a.first_error_on("/b"), Some("b1"));
        assert_eq!(a.first_error_on("/c"), None);
        let mut b = Skips::new();
        b.note("/c", "c1");
        b.note("/a", "a2");
        a.merge(b);
        assert_eq!(a.first_error(), Some("b1"));
        assert_eq!(
            a.rows(),
            vec![
                SkipRow {
                    topic: "/a".into(),
                    count: 2,
                    first_error: "a1".into()
                },
                SkipRow {
                    topic: "/b".into(),
                    count: 2,
                    first_error: "b1".into()
                },
                SkipRow {
                    topic: "/c".into(),
                    count: 1,
                    first_error: "c1".into()
                },
            ]
        );
        assert_eq!(a.to_string(), "5 skipped (/a: 2, /b: 2, /c: 1); first: b1");
        let mut empty = Skips::new();
        let mut c = Skips::new();
        c.note("/x", "x1");
        empty.merge(c);
        assert_eq!(empty.first_error(), Some("x1"));
    }
}

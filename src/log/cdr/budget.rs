//! The bounds every walk over a payload applies before it allocates or reads an array: the
//! structure budget ([`tree_budget`]) and the checked element counts. One type for the tree
//! decoder ([`super::decode`]), the JSON writer ([`super::write_json`]) and the flat decoder
//! ([`super::flat`]), so that all three refuse exactly the same payloads.

use super::{CdrError, CdrErrorKind, Cursor, MAX_ZERO_SIZE_ELEMENTS, Result, tree_budget};

/// Bytes of structure one payload's walk may still take.
#[derive(Debug, Clone, Copy)]
pub(super) struct Budget {
    left: usize,
    payload: usize,
}

impl Budget {
    /// The whole budget of a payload of `payload_len` bytes (header included).
    pub fn new(payload_len: usize) -> Self {
        Budget {
            left: tree_budget(payload_len),
            payload: payload_len,
        }
    }

    /// What is left.
    pub fn left(&self) -> usize {
        self.left
    }

    /// The error of a walk that would exceed the budget.
    pub fn exceeded(&self) -> CdrError {
        CdrError::new(CdrErrorKind::TreeTooLarge {
            budget: tree_budget(self.payload),
            payload: self.payload,
        })
    }

    /// Take `bytes` of structure from what is left.
    pub fn charge(&mut self, bytes: usize) -> Result<()> {
        self.left = self
            .left
            .checked_sub(bytes)
            .ok_or_else(|| self.exceeded())?;
        Ok(())
    }

    /// An array or sequence length, checked before anything is allocated for it: its
    /// elements must fit in the bytes left after `cur` (`min_elem_size` each), or, when they
    /// take no bytes at all, be at most [`MAX_ZERO_SIZE_ELEMENTS`]; `slot` bytes of structure
    /// are charged per element.
    pub fn check_len(
        &mut self,
        cur: &Cursor<'_>,
        n: usize,
        min_elem_size: usize,
        slot: usize,
    ) -> Result<usize> {
        if min_elem_size == 0 && n > MAX_ZERO_SIZE_ELEMENTS {
            return Err(CdrError::new(CdrErrorKind::TooManyEmpty { len: n as u64 }));
        }
        cur.check_fits(n, min_elem_size)?;
        self.charge(n.saturating_mul(slot))?;
        Ok(n)
    }

    /// A sequence's u32 length prefix, read from `cur` and checked as by
    /// [`Budget::check_len`].
    pub fn seq_len(
        &mut self,
        cur: &mut Cursor<'_>,
        min_elem_size: usize,
        slot: usize,
    ) -> Result<usize> {
        let len = cur.u32()? as usize;
        self.check_len(cur, len, min_elem_size, slot)
    }
}

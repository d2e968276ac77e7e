//! Dynamic load balancing: the row blocks still to compute, dealt one at a time to the rank
//! that asks (a rank that finishes early asks again), with the block each rank holds, so
//! that a failure can name it.

use std::collections::{BTreeMap, VecDeque};
use std::ops::Range;

/// The default rows per block for `n` rows over `ranks` ranks: about eight blocks a rank,
/// so that a rank given the costly rows is not the one everybody waits for, and at most
/// 256 rows (a block of 256 rows of 100,000 elements is 100 MB in flight), at least 1.
pub fn default_block_rows(n: usize, ranks: usize) -> usize {
    (n / (8 * ranks.max(1))).clamp(1, 256)
}

/// The blocks of a job: to deal, dealt (by rank), done.
#[derive(Debug)]
pub struct Dealer {
    pending: VecDeque<Range<usize>>,
    held: BTreeMap<usize, Range<usize>>,
    total: usize,
    done: usize,
}

impl Dealer {
    /// Rows 0..n in blocks of `block_rows` (the last shorter), less the rows of the blocks
    /// `finished` before (sorted, not overlapping): the gaps between them are cut into
    /// blocks of `block_rows` from their start. Blocks are dealt in row order.
    pub fn new(n: usize, block_rows: usize, finished: &[Range<usize>]) -> Dealer {
        let block_rows = block_rows.max(1);
        let mut pending = VecDeque::new();
        let mut start = 0;
        let mut gaps: Vec<Range<usize>> = Vec::new();
        for done in finished {
            if done.start > start {
                gaps.push(start..done.start);
            }
            start = start.max(done.end);
        }
        if start < n {
            gaps.push(start..n);
        }
        for gap in gaps {
            let mut s = gap.start;
            while s < gap.end {
                let e = (s + block_rows).min(gap.end);
                pending.push_back(s..e);
                s = e;
            }
        }
        Dealer {
            total: pending.len() + finished.len(),
            done: finished.len(),
            pending,
            held: BTreeMap::new(),
        }
    }

    /// The next block for `rank`, now held by it; `None` when none is left to deal.
    ///
    /// # Panics
    /// If `rank` still holds a block (a rank asks once it has returned its block).
    pub fn deal(&mut self, rank: usize) -> Option<Range<usize>> {
        assert!(!self.held.contains_key(&rank), "rank {rank} asked twice");
        let block = self.pending.pop_front()?;
        self.held.insert(rank, block.clone());
        Some(block)
    }

    /// The block `rank` held, now done; `None` if it held none.
    pub fn finish(&mut self, rank: usize) -> Option<Range<usize>> {
        let block = self.held.remove(&rank)?;
        self.done += 1;
        Some(block)
    }

    /// The block `rank` holds.
    pub fn held_by(&self, rank: usize) -> Option<&Range<usize>> {
        self.held.get(&rank)
    }

    /// Every (rank, block) dealt and not yet done, by rank.
    pub fn held(&self) -> impl Iterator<Item = (usize, &Range<usize>)> {
        self.held.iter().map(|(&r, b)| (r, b))
    }

    /// Blocks done (those finished before included).
    pub fn done(&self) -> usize {
        self.done
    }

    /// Blocks in all (those finished before included).
    pub fn total(&self) -> usize {
        self.total
    }

    /// True when every block is done.
    pub fn is_done(&self) -> bool {
        self.pending.is_empty() && self.held.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every row is dealt exactly once, in blocks of the size asked, around the blocks
    /// finished before.
    #[test]
    fn the_gaps_between_finished_blocks_are_dealt_once() {
        let mut dealer = Dealer::new(23, 4, &[2..5, 12..20]);
        let mut dealt = Vec::new();
        while let Some(b) = dealer.deal(1) {
            dealt.push(b);
            dealer.finish(1);
        }
        assert_eq!(dealt, vec![0..2, 5..9, 9..12, 20..23]);
        assert_eq!((dealer.done(), dealer.total()), (6, 6));
        assert!(dealer.is_done());
    }

    /// A rank that asks first gets the next block; what each holds is known until it
    /// returns it, and the job is not done while a block is held.
    #[test]
    fn blocks_go_to_whoever_asks_and_are_held_until_returned() {
        let mut dealer = Dealer::new(10, 3, &[]);
        assert_eq!(dealer.deal(2), Some(0..3));
        assert_eq!(dealer.deal(0), Some(3..6));
        assert_eq!(dealer.finish(0), Some(3..6));
        assert_eq!(dealer.deal(0), Some(6..9));
        assert_eq!(dealer.deal(1), Some(9..10));
        assert_eq!(dealer.deal(3), None);
        assert!(!dealer.is_done());
        assert_eq!(
            dealer.held().collect::<Vec<_>>(),
            vec![(0, &(6..9)), (1, &(9..10)), (2, &(0..3))]
        );
        for r in 0..3 {
            dealer.finish(r);
        }
        assert!(dealer.is_done());
        assert_eq!(dealer.finish(3), None);
    }

    #[test]
    fn default_blocks_are_about_eight_a_rank_within_1_and_256_rows() {
        assert_eq!(default_block_rows(1600, 2), 100);
        assert_eq!(default_block_rows(5, 4), 1);
        assert_eq!(default_block_rows(1_000_000, 4), 256);
    }
}

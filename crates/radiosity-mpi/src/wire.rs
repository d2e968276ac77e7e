//! The messages between rank 0 (the dealer and writer) and the other ranks, as bytes.
//!
//! A rank says [`Tag::Ready`] with its mesh fingerprint and element count (rank 0 refuses
//! a rank that meshed the scene differently), then gets [`Tag::Assign`] (a block of rows)
//! or [`Tag::Stop`]; it answers an assignment with [`Tag::Result`] (the block's rows, its
//! ray count and entries; for upper-triangle blocks only the entries after the diagonal), which asks for the next block too, or with [`Tag::Failed`] (what
//! went wrong, UTF-8).

use std::ops::Range;

/// Message tags (MPI tags).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i32)]
pub enum Tag {
    /// Rank to rank 0: ready for a block. Fingerprint u64, element count u64.
    Ready = 1,
    /// Rank to rank 0: a finished block. Start u64, end u64, rays u64, entries f32 (row
    /// by row; after the diagonal only for upper-triangle blocks).
    Result = 2,
    /// Rank to rank 0: the rank cannot go on. UTF-8 text.
    Failed = 3,
    /// Rank 0 to a rank: compute this block. Start u64, end u64.
    Assign = 10,
    /// Rank 0 to a rank: no more blocks.
    Stop = 11,
}

impl Tag {
    /// The tag of an MPI tag number.
    pub fn from_i32(tag: i32) -> Option<Tag> {
        [Tag::Ready, Tag::Result, Tag::Failed, Tag::Assign, Tag::Stop]
            .into_iter()
            .find(|t| *t as i32 == tag)
    }
}

/// A message that does not have the length its tag needs.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("a {tag:?} message of {len} bytes (expected {expected})")]
pub struct BadMessage {
    /// Its tag.
    pub tag: Tag,
    /// Its length.
    pub len: usize,
    /// What was expected.
    pub expected: String,
}

fn words<const K: usize>(bytes: &[u8]) -> [u64; K] {
    std::array::from_fn(|k| u64::from_le_bytes(bytes[8 * k..8 * k + 8].try_into().expect("8")))
}

fn put(words: &[u64]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// [`Tag::Ready`]'s bytes.
pub fn ready(fingerprint: u64, elements: usize) -> Vec<u8> {
    put(&[fingerprint, elements as u64])
}

/// (fingerprint, elements) of a [`Tag::Ready`] message.
pub fn read_ready(bytes: &[u8]) -> Result<(u64, usize), BadMessage> {
    if bytes.len() != 16 {
        return Err(BadMessage {
            tag: Tag::Ready,
            len: bytes.len(),
            expected: "16".into(),
        });
    }
    let [f, n] = words::<2>(bytes);
    Ok((f, n as usize))
}

/// [`Tag::Assign`]'s bytes.
pub fn assign(rows: &Range<usize>) -> Vec<u8> {
    put(&[rows.start as u64, rows.end as u64])
}

/// The rows of a [`Tag::Assign`] message.
pub fn read_assign(bytes: &[u8]) -> Result<Range<usize>, BadMessage> {
    if bytes.len() != 16 {
        return Err(BadMessage {
            tag: Tag::Assign,
            len: bytes.len(),
            expected: "16".into(),
        });
    }
    let [s, e] = words::<2>(bytes);
    Ok(s as usize..e as usize)
}

/// The entries of row `i` of `n` a [`Tag::Result`] message carries: those after the
/// diagonal where the blocks hold the upper triangle only (`upper`; the others are zeros
/// not worth sending: half the traffic), else all n.
fn sent(i: usize, n: usize, upper: bool) -> std::ops::Range<usize> {
    if upper {
        (i + 1).min(n)..n
    } else {
        0..n
    }
}

/// [`Tag::Result`]'s bytes for rows `rows` (`data` row-major, n entries a row).
pub fn result(rows: &Range<usize>, rays: u64, data: &[f32], n: usize, upper: bool) -> Vec<u8> {
    let mut bytes = put(&[rows.start as u64, rows.end as u64, rays]);
    for (k, i) in rows.clone().enumerate() {
        let row = &data[k * n..(k + 1) * n];
        bytes.extend(row[sent(i, n, upper)].iter().flat_map(|x| x.to_le_bytes()));
    }
    bytes
}

/// (rows, rays, entries) of a [`Tag::Result`] message from a matrix of `n` columns, the
/// rows whole again (zeros where `upper` left entries out).
pub fn read_result(
    bytes: &[u8],
    n: usize,
    upper: bool,
) -> Result<(Range<usize>, u64, Vec<f32>), BadMessage> {
    let bad = |expected: String| BadMessage {
        tag: Tag::Result,
        len: bytes.len(),
        expected,
    };
    if bytes.len() < 24 {
        return Err(bad("24 or more".into()));
    }
    let [s, e, rays] = words::<3>(bytes);
    let (s, e) = (s as usize, e as usize);
    if e < s || e > n {
        return Err(bad(format!("rows within 0..{n}, not {s}..{e}")));
    }
    let entries: usize = (s..e).map(|i| sent(i, n, upper).len()).sum();
    if bytes.len() - 24 != 4 * entries {
        return Err(bad(format!("24 + 4 x {entries} for rows {s}..{e}")));
    }
    let mut values = bytes[24..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4")));
    let mut data = vec![0.0f32; (e - s) * n];
    for (k, i) in (s..e).enumerate() {
        for f in &mut data[k * n..(k + 1) * n][sent(i, n, upper)] {
            *f = values.next().expect("counted above");
        }
    }
    Ok((s..e, rays, data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_round_trip() {
        assert_eq!(read_ready(&ready(0xabc, 412)), Ok((0xabc, 412)));
        assert_eq!(read_assign(&assign(&(40..60))), Ok(40..60));
        let data = [0.25f32, -0.0, f32::MIN_POSITIVE, 1.0, 0.5, 0.125];
        assert_eq!(
            read_result(&result(&(1..3), 99, &data, 3, false), 3, false),
            Ok((1..3, 99, data.to_vec()))
        );
        assert_eq!(Tag::from_i32(10), Some(Tag::Assign));
        assert_eq!(Tag::from_i32(4), None);
    }

    /// Upper-triangle blocks send the entries after the diagonal only: rows 1..3 of 4
    /// send 2 + 1 entries, and come back whole with zeros at and below the diagonal.
    #[test]
    fn upper_triangle_rows_send_only_the_entries_after_the_diagonal() {
        let data = [0.0f32, 0.0, 0.5, 0.25, 0.0, 0.0, 0.0, 0.125];
        let bytes = result(&(1..3), 7, &data, 4, true);
        assert_eq!(bytes.len(), 24 + 4 * 3);
        assert_eq!(read_result(&bytes, 4, true), Ok((1..3, 7, data.to_vec())));
    }

    /// A result whose entries do not fill its rows, or whose rows are not the matrix's, is
    /// refused, not misread.
    #[test]
    fn a_result_of_the_wrong_length_is_refused() {
        let mut bytes = result(&(1..3), 99, &[0.5; 6], 3, false);
        bytes.truncate(bytes.len() - 4);
        assert_eq!(
            read_result(&bytes, 3, false).unwrap_err().to_string(),
            "a Result message of 44 bytes (expected 24 + 4 x 6 for rows 1..3)"
        );
        let bytes = result(&(1..3), 99, &[0.5; 6], 3, false);
        assert_eq!(
            read_result(&bytes, 2, false).unwrap_err().to_string(),
            "a Result message of 48 bytes (expected rows within 0..2, not 1..3)"
        );
    }
}

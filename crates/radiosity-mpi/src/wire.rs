//! The messages between rank 0 (the dealer and writer) and the other ranks, as bytes.
//!
//! A rank says [`Tag::Ready`] with its mesh fingerprint and element count (rank 0 refuses
//! a rank that meshed the scene differently), then gets [`Tag::Assign`] (a block of rows)
//! or [`Tag::Stop`]; it answers an assignment with [`Tag::Result`] (the block's rows, its
//! ray count and entries), which asks for the next block too, or with [`Tag::Failed`] (what
//! went wrong, UTF-8).

use std::ops::Range;

/// Message tags (MPI tags).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i32)]
pub enum Tag {
    /// Rank to rank 0: ready for a block. Fingerprint u64, element count u64.
    Ready = 1,
    /// Rank to rank 0: a finished block. Start u64, end u64, rays u64, entries f32.
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

/// [`Tag::Result`]'s bytes.
pub fn result(rows: &Range<usize>, rays: u64, data: &[f32]) -> Vec<u8> {
    let mut bytes = put(&[rows.start as u64, rows.end as u64, rays]);
    bytes.reserve(4 * data.len());
    bytes.extend(data.iter().flat_map(|x| x.to_le_bytes()));
    bytes
}

/// (rows, rays, entries) of a [`Tag::Result`] message from a matrix of `n` columns.
pub fn read_result(bytes: &[u8], n: usize) -> Result<(Range<usize>, u64, Vec<f32>), BadMessage> {
    let bad = |expected: String| BadMessage {
        tag: Tag::Result,
        len: bytes.len(),
        expected,
    };
    if bytes.len() < 24 {
        return Err(bad("24 or more".into()));
    }
    let [s, e, rays] = words::<3>(bytes);
    let entries = (e.saturating_sub(s) as usize).saturating_mul(n);
    if e < s || bytes.len() - 24 != 4 * entries {
        return Err(bad(format!("24 + 4 x {entries} for rows {s}..{e}")));
    }
    let data = bytes[24..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4")))
        .collect();
    Ok((s as usize..e as usize, rays, data))
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
            read_result(&result(&(4..6), 99, &data), 3),
            Ok((4..6, 99, data.to_vec()))
        );
        assert_eq!(Tag::from_i32(10), Some(Tag::Assign));
        assert_eq!(Tag::from_i32(4), None);
    }

    /// A result whose entries do not fill its rows is refused, not misread.
    #[test]
    fn a_result_of_the_wrong_length_is_refused() {
        let bytes = result(&(4..6), 99, &[0.5; 5]);
        assert_eq!(
            read_result(&bytes, 3).unwrap_err().to_string(),
            "a Result message of 44 bytes (expected 24 + 4 x 6 for rows 4..6)"
        );
    }
}

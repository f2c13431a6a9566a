//! A workingstep's toolpath, stored compactly: a surfacing program has a million moves, and
//! each one costs 32 bytes here instead of a [`Move`]'s 72 or more.
//!
//! A move is kept as its end point, its source line with kind and phase packed beside it,
//! and an index into the toolpath's table of distinct feeds. The start point is the previous
//! move's end, except where it is not (the first move, a move after an offset change): those
//! start points and the arcs' geometry sit in side tables keyed by move index. Moves live in
//! fixed-size chunks, so the toolpath grows without copying and without spare capacity
//! beyond one chunk. Reading gives back every [`Move`] exactly as it was pushed. The tool
//! axis (5-axis moves) is a side table too: where it changes from +Z or from the one
//! before, the axis of the moves from there on ([`Toolpath::set_axis`], [`Toolpath::axis_at`]).

use std::collections::BTreeMap;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::model::{ArcGeometry, Move, MoveKind, P3, Phase};

/// Moves per chunk (32 bytes each: 128 KiB a chunk).
const CHUNK: usize = 4096;
/// Source lines are kept in the low 28 bits; a later line is kept as this one.
const LINE_MAX: u32 = (1 << 28) - 1;

#[derive(Clone, Copy, Debug)]
struct Packed {
    to: P3,
    /// Line (28 bits), kind (2 bits), phase (2 bits).
    line_kind_phase: u32,
    /// Index into `Toolpath::feeds`.
    feed: u32,
}

/// The moves of a workingstep, in order. See the module documentation for the layout.
#[derive(Clone, Default)]
pub struct Toolpath {
    chunks: Vec<Vec<Packed>>,
    len: usize,
    /// Distinct feeds, in order of first use, and where each is in it (by bits).
    feeds: Vec<f64>,
    feed_index: BTreeMap<u64, u32>,
    /// Arcs, by move index, ascending.
    arcs: Vec<(u32, ArcGeometry)>,
    /// Start points that are not the previous move's end, by move index, ascending.
    starts: Vec<(u32, P3)>,
    /// The tool axis from a move on, where it changes (+Z before the first), ascending.
    axes: Vec<(u32, P3)>,
}

/// The tool axis where none was stated.
const Z_AXIS: P3 = [0.0, 0.0, 1.0];

fn kind_bits(k: MoveKind) -> u32 {
    match k {
        MoveKind::Rapid => 0,
        MoveKind::Line => 1,
        MoveKind::Arc => 2,
    }
}

fn phase_bits(p: Phase) -> u32 {
    match p {
        Phase::Approach => 0,
        Phase::Cut => 1,
        Phase::Connect => 2,
        Phase::Retract => 3,
    }
}

impl Packed {
    fn line(&self) -> u32 {
        self.line_kind_phase & LINE_MAX
    }

    fn kind(&self) -> MoveKind {
        match (self.line_kind_phase >> 28) & 3 {
            0 => MoveKind::Rapid,
            1 => MoveKind::Line,
            _ => MoveKind::Arc,
        }
    }

    fn phase(&self) -> Phase {
        match self.line_kind_phase >> 30 {
            0 => Phase::Approach,
            1 => Phase::Cut,
            2 => Phase::Connect,
            _ => Phase::Retract,
        }
    }

    fn set_phase(&mut self, p: Phase) {
        self.line_kind_phase = (self.line_kind_phase & !(3 << 30)) | (phase_bits(p) << 30);
    }
}

fn find<T: Copy>(table: &[(u32, T)], i: usize) -> Option<T> {
    table.binary_search_by_key(&(i as u32), |e| e.0).ok().map(|k| table[k].1)
}

impl Toolpath {
    /// An empty toolpath.
    pub fn new() -> Toolpath {
        Toolpath::default()
    }

    /// Number of moves.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are no moves.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn packed(&self, i: usize) -> &Packed {
        &self.chunks[i / CHUNK][i % CHUNK]
    }

    /// Appends a move.
    pub fn push(&mut self, m: Move) {
        let i = self.len;
        assert!(i < u32::MAX as usize, "a toolpath holds fewer than 2^32 moves");
        // Compared by bits: a start at -0 after an end at 0 is kept as it was.
        if i == 0 || self.packed(i - 1).to.map(f64::to_bits) != m.from.map(f64::to_bits) {
            self.starts.push((i as u32, m.from));
        }
        if let Some(a) = m.arc {
            self.arcs.push((i as u32, a));
        }
        let bits = m.feed.to_bits();
        let feed = match self.feed_index.get(&bits) {
            Some(k) => *k,
            None => {
                let k = self.feeds.len() as u32;
                self.feeds.push(m.feed);
                self.feed_index.insert(bits, k);
                k
            }
        };
        let packed =
            Packed { to: m.to, line_kind_phase: m.line.min(LINE_MAX) | (kind_bits(m.kind) << 28) | (phase_bits(m.phase) << 30), feed };
        if self.chunks.last().is_none_or(|c| c.len() == CHUNK) {
            self.chunks.push(Vec::with_capacity(CHUNK));
        }
        self.chunks.last_mut().expect("a chunk was just made").push(packed);
        self.len += 1;
    }

    /// The move at `i`.
    pub fn get(&self, i: usize) -> Option<Move> {
        if i >= self.len {
            return None;
        }
        let p = self.packed(i);
        let from = find(&self.starts, i).unwrap_or_else(|| self.packed(i - 1).to);
        Some(Move {
            kind: p.kind(),
            phase: p.phase(),
            from,
            to: p.to,
            arc: if p.kind() == MoveKind::Arc { find(&self.arcs, i) } else { None },
            feed: self.feeds[p.feed as usize],
            line: p.line(),
        })
    }

    /// Sets the tool axis (unit, from the tip towards the holder) of the moves pushed from
    /// now on.
    pub fn set_axis(&mut self, axis: P3) {
        let now = self.axes.last().map_or(Z_AXIS, |e| e.1);
        if now.map(f64::to_bits) == axis.map(f64::to_bits) {
            return;
        }
        let i = self.len as u32;
        if self.axes.last().is_some_and(|e| e.0 == i) {
            self.axes.pop();
        }
        if self.axes.last().map_or(Z_AXIS, |e| e.1).map(f64::to_bits) != axis.map(f64::to_bits) {
            self.axes.push((i, axis));
        }
    }

    /// The tool axis of the move at `i` (+Z where none was stated).
    pub fn axis_at(&self, i: usize) -> P3 {
        let k = self.axes.partition_point(|e| e.0 as usize <= i);
        k.checked_sub(1).map_or(Z_AXIS, |k| self.axes[k].1)
    }

    /// Whether any move's tool axis is not +Z.
    pub fn tilts(&self) -> bool {
        !self.axes.is_empty()
    }

    /// The first move.
    pub fn first(&self) -> Option<Move> {
        self.get(0)
    }

    /// The last move.
    pub fn last(&self) -> Option<Move> {
        self.len.checked_sub(1).and_then(|i| self.get(i))
    }

    /// The phase of the move at `i` (cheaper than [`get`](Self::get)).
    pub fn phase(&self, i: usize) -> Option<Phase> {
        (i < self.len).then(|| self.packed(i).phase())
    }

    /// Sets the phase of the move at `i`.
    pub fn set_phase(&mut self, i: usize, phase: Phase) {
        if i < self.len {
            self.chunks[i / CHUNK][i % CHUNK].set_phase(phase);
        }
    }

    /// The moves in order, by value.
    pub fn iter(&self) -> Iter<'_> {
        Iter { tp: self, i: 0, end: self.len, prev: None, start_k: 0, arc_k: 0 }
    }

    /// Removes the moves from `at` on and returns them, start points kept.
    pub fn split_off(&mut self, at: usize) -> Toolpath {
        let mut tail = Toolpath::new();
        if at >= self.len {
            return tail;
        }
        for (i, m) in self.iter().enumerate().skip(at) {
            tail.set_axis(self.axis_at(i));
            tail.push(m);
        }
        self.truncate(at);
        tail
    }

    /// Keeps the first `n` moves.
    pub fn truncate(&mut self, n: usize) {
        if n >= self.len {
            return;
        }
        let chunks = n.div_ceil(CHUNK);
        self.chunks.truncate(chunks);
        if let Some(c) = self.chunks.last_mut() {
            c.truncate(n - (chunks - 1) * CHUNK);
        }
        self.len = n;
        self.starts.retain(|e| (e.0 as usize) < n);
        self.arcs.retain(|e| (e.0 as usize) < n);
        self.axes.retain(|e| (e.0 as usize) < n);
        // Feeds no move uses any more stay in the table; they are not seen from outside.
    }
}

impl std::fmt::Debug for Toolpath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl PartialEq for Toolpath {
    fn eq(&self, other: &Toolpath) -> bool {
        self.len == other.len && self.iter().eq(other.iter()) && self.axes == other.axes
    }
}

impl FromIterator<Move> for Toolpath {
    fn from_iter<I: IntoIterator<Item = Move>>(iter: I) -> Toolpath {
        let mut t = Toolpath::new();
        for m in iter {
            t.push(m);
        }
        t
    }
}

impl From<Vec<Move>> for Toolpath {
    fn from(v: Vec<Move>) -> Toolpath {
        v.into_iter().collect()
    }
}

impl Extend<Move> for Toolpath {
    fn extend<I: IntoIterator<Item = Move>>(&mut self, iter: I) {
        for m in iter {
            self.push(m);
        }
    }
}

/// The moves of a [`Toolpath`], in order, by value.
#[derive(Clone)]
pub struct Iter<'a> {
    tp: &'a Toolpath,
    i: usize,
    end: usize,
    prev: Option<P3>,
    start_k: usize,
    arc_k: usize,
}

impl Iterator for Iter<'_> {
    type Item = Move;

    fn next(&mut self) -> Option<Move> {
        if self.i >= self.end {
            return None;
        }
        let (i, tp) = (self.i, self.tp);
        let p = tp.packed(i);
        // Side tables are read in step; a jump ahead (nth) looks them up.
        let from = match tp.starts.get(self.start_k) {
            Some(&(k, s)) if k as usize == i => {
                self.start_k += 1;
                s
            }
            _ => self.prev.unwrap_or_else(|| tp.get(i).map_or(p.to, |m| m.from)),
        };
        let arc = if p.kind() == MoveKind::Arc {
            match tp.arcs.get(self.arc_k) {
                Some(&(k, a)) if k as usize == i => {
                    self.arc_k += 1;
                    Some(a)
                }
                _ => find(&tp.arcs, i),
            }
        } else {
            None
        };
        self.prev = Some(p.to);
        self.i += 1;
        Some(Move { kind: p.kind(), phase: p.phase(), from, to: p.to, arc, feed: tp.feeds[p.feed as usize], line: p.line() })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.end - self.i;
        (n, Some(n))
    }

    fn nth(&mut self, n: usize) -> Option<Move> {
        if n == 0 {
            return self.next();
        }
        self.i = self.i.saturating_add(n).min(self.end);
        self.prev = None;
        let i = self.i as u32;
        self.start_k = self.tp.starts.partition_point(|e| e.0 < i);
        self.arc_k = self.tp.arcs.partition_point(|e| e.0 < i);
        self.next()
    }
}

impl ExactSizeIterator for Iter<'_> {}

impl DoubleEndedIterator for Iter<'_> {
    fn next_back(&mut self) -> Option<Move> {
        if self.i >= self.end {
            return None;
        }
        self.end -= 1;
        self.tp.get(self.end)
    }
}

impl<'a> IntoIterator for &'a Toolpath {
    type Item = Move;
    type IntoIter = Iter<'a>;

    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

impl Serialize for Toolpath {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.iter())
    }
}

impl<'de> Deserialize<'de> for Toolpath {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Toolpath, D::Error> {
        struct Moves;
        impl<'de> serde::de::Visitor<'de> for Moves {
            type Value = Toolpath;

            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a list of moves")
            }

            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Toolpath, A::Error> {
                let mut t = Toolpath::new();
                while let Some(m) = seq.next_element::<Move>()? {
                    t.push(m);
                }
                Ok(t)
            }
        }
        d.deserialize_seq(Moves)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mv(kind: MoveKind, from: P3, to: P3, feed: f64, line: u32) -> Move {
        let arc = (kind == MoveKind::Arc).then_some(ArcGeometry { center: [0.0, 0.0, from[2]], axis: [0.0, 0.0, 1.0], turns: 1 });
        Move { kind, phase: Phase::Cut, from, to, arc, feed, line }
    }

    #[test]
    fn moves_read_back_exactly_across_chunks_jumps_and_arcs() {
        let mut moves = Vec::new();
        let mut at = [0.0, 0.0, 5.0];
        for i in 0..(3 * CHUNK as u32 + 17) {
            let kind = [MoveKind::Rapid, MoveKind::Line, MoveKind::Arc][(i % 3) as usize];
            // Every 1000th move starts elsewhere (an offset change between moves).
            let from = if i % 1000 == 999 { [at[0] + 0.5, at[1], at[2]] } else { at };
            let to = [f64::from(i) * 0.1, f64::from(i % 7), -f64::from(i % 5) * 0.25];
            let mut m = mv(kind, from, to, f64::from(100 + i % 4), i + 1);
            m.phase = [Phase::Approach, Phase::Cut, Phase::Connect, Phase::Retract][(i % 4) as usize];
            moves.push(m);
            at = to;
        }
        let t: Toolpath = moves.clone().into();
        assert_eq!(t.len(), moves.len());
        assert_eq!(t.iter().collect::<Vec<_>>(), moves);
        assert_eq!(t.iter().rev().collect::<Vec<_>>(), moves.iter().rev().cloned().collect::<Vec<_>>());
        for i in [0, 1, CHUNK - 1, CHUNK, 999, 1000, moves.len() - 1] {
            assert_eq!(t.get(i).as_ref(), moves.get(i), "move {i}");
            assert_eq!(t.iter().nth(i).as_ref(), moves.get(i), "nth {i}");
        }
        assert_eq!(t.get(moves.len()), None);
        // Split keeps each half's moves, start points included.
        let mut head = t.clone();
        let tail = head.split_off(CHUNK + 5);
        assert_eq!(head.iter().collect::<Vec<_>>(), moves[..CHUNK + 5]);
        assert_eq!(tail.iter().collect::<Vec<_>>(), moves[CHUNK + 5..]);
        // JSON is that of the moves.
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(json, serde_json::to_string(&moves).unwrap());
        // (serde_json reads reals to within an ulp, so the check is against the moves read back.)
        let back: Toolpath = serde_json::from_str::<Vec<Move>>(&json).unwrap().into();
        assert_eq!(serde_json::from_str::<Toolpath>(&json).unwrap(), back);
    }

    #[test]
    fn phases_change_in_place_and_a_move_is_32_bytes() {
        let mut t: Toolpath = vec![mv(MoveKind::Line, [0.0; 3], [1.0, 0.0, 0.0], 10.0, u32::MAX)].into();
        t.set_phase(0, Phase::Retract);
        let m = t.get(0).unwrap();
        assert_eq!((m.phase, m.kind, m.line, m.feed), (Phase::Retract, MoveKind::Line, LINE_MAX, 10.0));
        assert_eq!(std::mem::size_of::<Packed>(), 32);
    }
}

//! The packed 8-byte kd-tree node.
//!
//! `flags` holds the node kind in its two low bits (0, 1, 2 = split axis of an interior node,
//! 3 = leaf) and a 30-bit number above them: the above child's index for an interior node,
//! the primitive count for a leaf. `payload` is the split position's bits for an interior node,
//! and for a leaf either its only primitive (count 1) or the offset of its run in the tree's
//! primitive index array. Eight bytes keep eight nodes to a cache line.

const LEAF: u32 = 3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct KdNode {
    payload: u32,
    flags: u32,
}

impl KdNode {
    /// Largest child index or leaf primitive count that fits beside the two kind bits.
    pub const MAX_INDEX: u32 = (1 << 30) - 1;

    #[inline]
    pub fn interior(axis: usize, split: f32, above: u32) -> Self {
        debug_assert!(axis < 3);
        assert!(above <= Self::MAX_INDEX, "kd-tree has too many nodes");
        Self {
            payload: split.to_bits(),
            flags: (above << 2) | axis as u32,
        }
    }

    /// A leaf of `count` primitives; `first` is the primitive itself when `count == 1`,
    /// otherwise the offset of the leaf's run in the primitive index array.
    #[inline]
    pub fn leaf(count: u32, first: u32) -> Self {
        assert!(
            count <= Self::MAX_INDEX,
            "kd-tree leaf has too many primitives"
        );
        Self {
            payload: first,
            flags: (count << 2) | LEAF,
        }
    }

    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.flags & 3 == LEAF
    }

    /// A leaf without primitives.
    #[inline]
    pub fn is_empty_leaf(&self) -> bool {
        self.flags == LEAF
    }

    #[inline]
    pub fn axis(&self) -> usize {
        (self.flags & 3) as usize
    }

    #[inline]
    pub fn split(&self) -> f32 {
        f32::from_bits(self.payload)
    }

    #[inline]
    pub fn above(&self) -> u32 {
        self.flags >> 2
    }

    #[inline]
    pub fn prim_count(&self) -> u32 {
        self.flags >> 2
    }

    /// This node moved `nodes` places on in the node array, with its leaf runs moved `indices`
    /// places on in the index array.
    #[inline]
    pub fn shifted(self, nodes: u32, indices: u32) -> Self {
        if self.is_leaf() {
            if self.prim_count() > 1 {
                return Self::leaf(self.prim_count(), self.payload + indices);
            }
            self
        } else {
            Self::interior(self.axis(), self.split(), self.above() + nodes)
        }
    }

    /// The node as one word (payload low, flags high), for selects between whole nodes.
    #[inline(always)]
    pub fn bits(self) -> u64 {
        u64::from(self.payload) | u64::from(self.flags) << 32
    }

    /// The node of [`KdNode::bits`].
    #[inline(always)]
    pub fn from_bits(b: u64) -> Self {
        Self {
            payload: b as u32,
            flags: (b >> 32) as u32,
        }
    }

    /// Payload and flags, for exact comparisons of trees.
    pub fn words(&self) -> [u32; 2] {
        [self.payload, self.flags]
    }

    /// The inline primitive (count 1) or the run offset (count > 1), by reference so that a
    /// one-primitive leaf can be handed out as a one-element slice.
    #[inline]
    pub fn payload(&self) -> &u32 {
        &self.payload
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_is_eight_bytes() {
        assert_eq!(std::mem::size_of::<KdNode>(), 8);
    }

    #[test]
    fn interior_round_trips() {
        for axis in 0..3 {
            for split in [
                0.0f32,
                -0.0,
                1.5,
                -3.25e-7,
                1e30,
                -f32::MAX,
                f32::MIN_POSITIVE,
            ] {
                for above in [1u32, 2, 12345, KdNode::MAX_INDEX] {
                    let n = KdNode::interior(axis, split, above);
                    assert!(!n.is_leaf());
                    assert_eq!(n.axis(), axis);
                    assert_eq!(n.split().to_bits(), split.to_bits());
                    assert_eq!(n.above(), above);
                }
            }
        }
    }

    #[test]
    fn leaf_round_trips() {
        for count in [0u32, 1, 2, 7, KdNode::MAX_INDEX] {
            for first in [0u32, 1, 99, u32::MAX] {
                let n = KdNode::leaf(count, first);
                assert!(n.is_leaf());
                assert_eq!(n.prim_count(), count);
                assert_eq!(*n.payload(), first);
            }
        }
    }

    #[test]
    fn bits_round_trip() {
        for n in [
            KdNode::interior(2, -1.5, 77),
            KdNode::leaf(0, 0),
            KdNode::leaf(9, 1234),
        ] {
            assert_eq!(KdNode::from_bits(n.bits()), n);
        }
        assert!(KdNode::from_bits(KdNode::leaf(0, 5).bits()).is_empty_leaf());
    }

    #[test]
    #[should_panic]
    fn oversized_child_index_panics() {
        let _ = KdNode::interior(0, 0.0, KdNode::MAX_INDEX + 1);
    }
}

//! The binary tree's nodes as the builder makes them: 32 bytes, siblings in pairs. Traversal
//! reads the tree collapsed into wide nodes (`wide.rs`).

use glam::Vec3;

/// One node as the builder makes it: a box, and either two children (adjacent: a
/// [`NodePair`]) or a run of triangles. 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct Node {
    pub(crate) min: Vec3,
    /// Leaf: index of its first triangle in leaf order. Interior: index of its first child
    /// (even; the second child follows it in the same pair).
    pub(crate) offset: u32,
    pub(crate) max: Vec3,
    /// Leaf: number of triangles (at least 1). Interior: 0.
    pub(crate) count: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);

/// Two sibling nodes, as built.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct NodePair(pub(crate) [Node; 2]);

impl Node {
    /// Filler for the root's pair (never visited).
    pub(crate) const UNUSED: Node = Node {
        min: Vec3::INFINITY,
        offset: 0,
        max: Vec3::NEG_INFINITY,
        count: 0,
    };

    #[inline]
    pub(super) fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

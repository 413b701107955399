//! Exact neighbour searches, the structures the filters stand on (PCL's
//! `search` and `octree` modules, FLANN's k-d tree):
//!
//! | structure | for | used by |
//! |---|---|---|
//! | [`columns`]: a grid of height-sorted columns | dense scans of even density | radius and statistical removal, smoothing |
//! | [`kdtree`]: FLANN's single k-d tree | any cloud; the reference the others are tested against | normals, clouds the grid declines |
//! | [`octree`]: Morton-ordered points, groups searched on one gather | clouds whose density varies widely | statistical removal |
//!
//! Every structure gives the same squared distances, bit for bit, in f32
//! in FLANN's order ([`within`], the distance kernels they share), so a
//! filter keeps PCL's points whichever search it takes; [`bounds`] widens
//! their boxes past f32 rounding.

pub(crate) mod bounds;
pub(crate) mod columns;
pub(crate) mod kdtree;
pub(crate) mod octree;
pub(crate) mod within;

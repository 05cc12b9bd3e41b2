//! LAST RESORT (dissertation chapter 3): fill cavities by exhaustive search, and recover missing
//! surface triangles of a tet mesh by carving and refilling cavities, without new points on the
//! surface.
//!
//! - [`search`]: Algorithm 3.1, the search that fills a closed cavity shell with tets whose
//!   corners are cavity points ([`fill`], [`Searcher`]).
//! - [`recover`](mod@recover): Algorithm 3.2, the boundary recovery driver ([`recover()`]).
//! - [`improve`](mod@improve): sliver removal with the same search (section 3.4, [`improve()`]).
//!
//! Every combinatorial decision is an exact predicate (orient3d, exact segment–triangle and
//! triangle–triangle tests); floating point only ranks tets by quality.

pub(crate) mod cells;
pub mod improve;
pub(crate) mod kernel;
pub mod recover;
pub mod search;

pub use improve::{ImproveOptions, ImproveReport, Metric, MoveCounts, improve};
pub use recover::{Domain, RecoverError, RecoverOptions, RecoverReport, Unrecovered, recover};

pub use search::{Fill, SearchError, SearchOptions, Searcher, fill};

//! Whole-mesh quality reports (filled in by the quality work).

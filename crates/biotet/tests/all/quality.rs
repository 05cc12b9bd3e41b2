//! Tests: quality.

//! Tests: predicates.

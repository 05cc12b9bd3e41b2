//! Exact intersection tests built from orientation predicates.

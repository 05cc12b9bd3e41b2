//! Surface validation.

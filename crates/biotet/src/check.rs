//! The validity checker (filled in below).

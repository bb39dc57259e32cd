//! Image files (placeholder until written).

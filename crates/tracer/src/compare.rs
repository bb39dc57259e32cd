//! Image comparison statistics (placeholder until written).

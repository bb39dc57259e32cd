//! mcc placeholder

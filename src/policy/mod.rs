//! The policies the engine is configured with: the cost of a collapse (and where the kept
//! vertex goes), its legality, the error bound, and the feature rule.

pub mod bound;
pub mod cost;
mod envelope;
pub(crate) mod feature;
pub mod legality;

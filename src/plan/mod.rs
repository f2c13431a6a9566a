//! Plan recovery: canonical ops → workingsteps with tools, technology and toolpaths, then
//! features (planar faces, holes, pockets, slots, steps, profiles) with their operations.

mod describe;
pub mod feature;
pub mod geom;
mod model;
mod recover;
pub mod risk;
mod toolpath;
pub mod tooltable;

pub use describe::describe;
pub use model::*;
pub use recover::{Recoverer, ToolFacts, measure, parse_stock, parse_tool_comment, recover, round_sig};
pub use toolpath::{Iter as ToolpathIter, Toolpath};

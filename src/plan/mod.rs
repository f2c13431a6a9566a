//! Plan recovery: canonical ops → workingsteps with tools, technology and toolpaths.

pub mod geom;
mod model;
mod recover;

pub use model::*;
pub use recover::{parse_tool_comment, recover};

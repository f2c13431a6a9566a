//! Views for the planners' workspace, computed from plans and program text in the pure core:
//! toolpath pictures (`picture`) and source listings (`source`). No IO; the web layer and the
//! HTML report render what these return.

pub mod picture;
pub mod source;

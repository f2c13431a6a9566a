//! Views for the planners' workspace, computed from plans and program text in the pure core:
//! toolpath pictures (`picture`) and source listings (`source`). No IO; the web layer and the
//! HTML report render what these return.
//!
//! pure views for the planners' workspace: `picture.rs` draws the original's
//! and the edited program's toolpaths overlaid as SVG (top, front, side): `pictures` reads
//! each toolpath once for all views, projects each point to pixels and simplifies each
//! polyline as its points come (`Pen`: a cone test, every dropped point within half a pixel
//! of its drawn segment, reversals included; constant memory, one square root a point),
//! rapids and feeds apart, start points marked, one layer per workingstep and program
//! (`data-layer="o1"`, `e1`). A change's moves (in its region's box, from its first changed
//! line on) are drawn exactly, every end point (class `chg`), up to `EXACT_MOVES` per region
//! and program; beyond that (a change over the whole part) within a quarter pixel, and a
//! `text.note` in the picture gives the counts. Each changed region is boxed
//! (`region-{view}-{change id}`, linked to `#change-{id}`). `source.rs` colours G-code
//! by token, normalizes a line as the machine reads it (no block numbers, comments, blanks;
//! one number spelling) and aligns two programs' lines (common start and end, then an LCS of
//! the normalized lines) so a cosmetic difference is told from a real one; `windows` picks
//! the lines to show of a long program; `visible` writes bidirectional controls out
//! (`[U+202E]`).

pub mod picture;
pub mod source;

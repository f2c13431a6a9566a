//! Plan recovery: canonical ops → workingsteps with tools, technology and toolpaths, then
//! features (planar faces, holes, pockets, slots, steps, profiles) with their operations.
//!
//! `model.rs` (`ProcessPlan`, `Workingstep`, `Tool`, `Technology`, `Move`,
//! `Feature`, `Stock`; ISO 14649 `Operation`s and `Strategy`; each workingstep's
//! `MachineState`: work offset, offset numbers that are not the tool's own, compensation
//! side, stops, dwells, optional-block lines, a feed override switched off), `toolpath.rs`
//! (a workingstep's `Toolpath`: 32 bytes a move — end point, line with kind and phase, an
//! index into its distinct feeds — in fixed chunks, with start points that are not the
//! previous end and arc geometry in side tables; it gives back each `Move` by value, exactly
//! as pushed, and serialises as the list of moves), `recover.rs` (segmentation into
//! workingsteps at tool, family, work offset and technology changes — a retract followed by
//! cutting at another feed starts a new one, and so does, with the same feed, a depth
//! sequence that restarts, a re-entry where the deepest level began after several levels (a
//! finishing pass) or an entry outside the region cut so far; holes made by explicit moves
//! (every feed along the tool axis, a tool that is no milling cutter) become hole making,
//! the operation from the tool kind and the motion; phases; tool facts from the table, CAM
//! comments (near the change; else one naming the tool — `T3 D=10. ...`, `TOOL 3`, Mastercam
//! `T3 | 10. FLAT ENDMILL | H3 | D3` — or naming none, since the previous operation's last cut,
//! nearest first; else the header tool list), APT tool statements (`TLDATA/MILL,d,r,...`,
//! `CUTTER/d,r,...`, in program units), `T="name"`, or usage;
//! stock from config, a blank the program defines (`BLK FORM`, `WORKPIECE`, passed on by the
//! interpreter as a stock comment) or a CAM comment, placed by a stock origin comment; `measure` derives what a toolpath determines; under
//! constant surface speed the technology keeps the surface speed and a feed per revolution
//! follows the tool's distance from the turning axis up to the speed limit),
//! `feature/` (features from the deepest level's horizontal cuts: parallel passes → planar
//! face / step / pocket, nested loops → closed pocket (or, entered from outside, an outside
//! profile whose wall is the innermost), one loop → pocket wall or outside profile (a loop tighter than the tool is a pocket's) by
//! where any entry (plunge, ramp, helix) went down, else the compensation side, the climb-milling side
//! only as a last resort (and then no cut mode); a loop the control leaves short of its start
//! under compensation is closed on its line; collinear pieces join, four quarter arcs give a
//! rectangle's corner radius, two half circles a slot; paths entering and leaving the stock
//! across one side an open pocket; one pass along a stock side a step; plunges only a flat
//! hole; the top from the faced level, the stock, the layers or the program zero, never the R
//! level; a spiral, a slot; merging rough/finish and drill/ream workingsteps into one feature
//! with allowances, spot drilling into the holes it marks; hole depths to where the full
//! diameter ends; each feature's `Sources` say where its size, top and point angle came from,
//! and an unknown tool leaves a size unknown with the tool-centre path said),
//! `turned.rs` (the turning model: operations, cycle values, turned features), `turning.rs`
//! (a program that turns about Z: its workingsteps named from their lathe cycles
//! or moves, ISO 14649-121, and its turned features, ISO 14649-12, in diameters),
//! `tooltable.rs` (the door `tooltable::read`: LinuxCNC `tool.tbl`, Heidenhain `TOOL.T`,
//! Fanuc `G10` offsets and Siemens `$TC_DP` data into the interpreter's `ToolData`, told from
//! the text; the shell reads the file, `config::read_tool_table`), `risk.rs` (risky settings — another tool's length
//! offset, none while cutting, a lone work offset — as `check` warnings and diff rows),
//! `setup.rs` (the tilted working plane a workingstep runs on, `Setup`: origin, axis and
//! reference direction in the part's frame, told as spatial angles; recovery starts a new
//! workingstep where it changes, keeps the toolpath in the plane's coordinates and places
//! the features on it in the part's frame with their own axis),
//! `geom.rs` (arc sweep, lengths, sampling, a point along a move, an arc's exact extremes
//! for boxes and depths, with nalgebra). Equal toolpaths give equal plans however they are
//! written: a feed that goes nowhere is no cut, an arc of several turns is its turns to
//! feature recognition, a dwell under half a millisecond is none, and in hole making the first
//! plunge is a cut.

mod describe;
pub mod feature;
pub mod geom;
mod model;
mod recover;
pub mod risk;
mod setup;
mod toolpath;
pub mod tooltable;
mod turned;
pub mod turning;

pub use describe::describe;
pub use model::*;
pub use recover::{Recoverer, ToolFacts, measure, parse_stock, parse_tool_comment, recover, round_sig};
pub use setup::Setup;
pub use toolpath::{Iter as ToolpathIter, Toolpath};
pub use turned::{TurnOp, Turned, Turning};

//! A turner's edits at the control told in the machine's own terms (issue 40 item 5, issue 41),
//! one golden per kind and control family: the rows of each edit were written by hand from
//! the two texts before ncplan ran. A change of an allowance, a depth of cut, a clamp or a
//! pitch never adds or removes a workingstep, a hole or a feature; explicit roughing passes
//! added or taken out are told as roughing passes; a program number, a comment or a block
//! renumbering stays silent.

use std::path::{Path, PathBuf};

use expect_test::expect;
use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs/lathe")
}

/// The rows of the edit `from` → `to` of a program in `tests/programs/lathe`, read with
/// `dialect`: `kind | field | before | after` and the planner's sentence.
fn edit(program: &str, dialect: &str, from: &str, to: &str) -> String {
    let a = std::fs::read_to_string(dir().join(program)).unwrap();
    assert!(a.contains(from), "{from:?} is in {program}");
    let b = a.replacen(from, to, 1);
    rows(dialect, &a, &b)
}

fn rows(dialect: &str, a: &str, b: &str) -> String {
    let d = Registry::shipped().get(dialect).unwrap();
    let profile = Profile::default();
    let (pa, pb) = (pipeline::analyze(a.as_bytes(), &d, &profile), pipeline::analyze(b.as_bytes(), &d, &profile));
    let (x, y) = (
        ncplan::diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
        ncplan::diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
    );
    let got = ncplan::diff::compare(x, y);
    let missing = ncplan::diff::unaccounted(x, y, &got);
    assert!(missing.is_empty(), "differing statements no change names: {missing:?}");
    let mut s = String::new();
    for c in &got {
        s.push_str(&format!("{} | {} | {} | {}\n  {}\n", c.kind.as_str(), c.field, c.before, c.after, c.phrase()));
    }
    s
}

/// A setting's edit adds or removes nothing.
fn no_structure_change(rows: &str) {
    if std::env::var_os("UPDATE_EXPECT").is_some() {
        return;
    }
    for word in
        ["workingstep_added", "workingstep_removed", "hole_added", "hole_removed", "hole_moved", "toolpath_changed", "statement_changed"]
    {
        assert!(!rows.contains(word), "{word} in\n{rows}");
    }
}

#[test]
fn fanuc_two_block_g71_and_g76() {
    let p = "fanuc_g71_shaft.nc";
    let retract = edit(p, "fanuc_lathe", "G71 U2. R0.5", "G71 U2. R1.");
    no_structure_change(&retract);
    expect![[r#"
        cycle_parameter_changed | retract | 0.5 | 1
          retract changed from 0.5 to 1 at line 10
    "#]]
    .assert_eq(&retract);
    let height = edit(p, "fanuc_lathe", "P920 Q300", "P1000 Q300");
    no_structure_change(&height);
    expect![[r#"
        cycle_parameter_changed | thread_height | 0.92 | 1
          thread height changed from 0.92 to 1 at line 32
    "#]]
    .assert_eq(&height);
    let first = edit(p, "fanuc_lathe", "Q300 F1.5", "Q250 F1.5");
    no_structure_change(&first);
    expect![[r#"
        cycle_parameter_changed | first_depth_of_cut | 0.3 | 0.25
          first depth of cut changed from 0.3 to 0.25 at line 32
    "#]]
    .assert_eq(&first);
    let spring = edit(p, "fanuc_lathe", "G76 P010060", "G76 P020060");
    no_structure_change(&spring);
    expect![[r#"
        cycle_parameter_changed | finishing_passes | 1 | 2
          finishing passes changed from 1 to 2 at line 31
    "#]]
    .assert_eq(&spring);
    let diameter = edit(p, "fanuc_lathe", "X24. Z-2.\nZ-30.", "X23.9 Z-2.\nZ-30.");
    expect![[r#"
        feature_changed | diameter | Ø24 | Ø23.9 (also in workingstep 2)
          diameter changed from Ø24 to Ø23.9 (also in workingstep 2) at line 14
    "#]]
    .assert_eq(&diameter);
    let wear = edit(p, "fanuc_lathe", "T0101 (OD ROUGH", "T0111 (OD ROUGH");
    expect![[r#"
        length_offset_changed | offset of tool 1 | 1 | 11
          offset of tool 1 changed from 1 to 11 at line 6
    "#]]
    .assert_eq(&wear);
    let quiet = rows(
        "fanuc_lathe",
        &std::fs::read_to_string(dir().join(p)).unwrap(),
        &std::fs::read_to_string(dir().join(p))
            .unwrap()
            .replace("O1001 (STEPPED SHAFT", "O1002 (SHAFT REV B")
            .replace("G00 X52. Z2. M08", "N5 G00 X52. Z2. M08 (APPROACH)"),
    );
    assert_eq!(quiet, "", "a program number, a comment and a block number are no change");
}

#[test]
fn fanuc_g92_and_g94() {
    let pitch = edit("fanuc_g92_thread.nc", "fanuc_lathe", "F2.", "F1.5");
    no_structure_change(&pitch);
    expect![[r#"
        thread_pitch_changed | thread_pitch | 2 | 1.5
          thread pitch changed from 2 to 1.5 at line 7
    "#]]
    .assert_eq(&pitch);
    let passes = edit("fanuc_g92_thread.nc", "fanuc_lathe", "X27.6\n", "");
    no_structure_change(&passes);
    expect![[r#"
        cycle_parameter_changed | thread_passes | 7 | 6
          thread passes changed from 7 to 6 at original line 12
    "#]]
    .assert_eq(&passes);
    let face = edit("fanuc_g94_face.nc", "fanuc_lathe", "Z0.\n", "Z-0.2\n");
    expect![[r#"
        feature_changed | face | Z0 | Z-0.2
          face changed from Z0 to Z-0.2 at line 9
    "#]]
    .assert_eq(&face);
    let clamp = edit("fanuc_g94_face.nc", "fanuc_lathe", "G50 S2200", "G50 S1800");
    no_structure_change(&clamp);
    expect![[r#"
        spindle_speed_changed | spindle_clamp | 2200 /min | 1800 /min
          spindle clamp changed from 2200 /min to 1800 /min at line 5
    "#]]
    .assert_eq(&clamp);
}

#[test]
fn haas_one_block_g71_and_g76() {
    let depth = edit("haas_g71.nc", "haas_lathe", "D0.06", "D0.05");
    no_structure_change(&depth);
    expect![[r#"
        axial_depth_changed | depth_of_cut | 0.06 | 0.05
          depth of cut changed from 0.06 to 0.05 at line 9
    "#]]
    .assert_eq(&depth);
    let allowance = edit("haas_g71.nc", "haas_lathe", "U0.02 W0.005", "U0.03 W0.01");
    no_structure_change(&allowance);
    expect![[r#"
        allowance_changed | finishing_allowance | U0.02 W0.005 | U0.03 W0.01
          finishing allowance changed from U0.02 W0.005 to U0.03 W0.01 at line 9
    "#]]
    .assert_eq(&allowance);
    let feed = edit("haas_g71.nc", "haas_lathe", "D0.06 F0.01", "D0.06 F0.008");
    no_structure_change(&feed);
    expect![[r#"
        feed_changed | feed | F0.01 in/rev | F0.008 in/rev
          feed changed from F0.01 in/rev to F0.008 in/rev at line 9
    "#]]
    .assert_eq(&feed);
    let speed = edit("haas_g71.nc", "haas_lathe", "G96 S600", "G96 S500");
    no_structure_change(&speed);
    expect![[r#"
        spindle_speed_changed | cutting_speed | 600 ft/min | 500 ft/min (also in workingstep 2)
          cutting speed changed from 600 ft/min to 500 ft/min (also in workingstep 2) at line 7
    "#]]
    .assert_eq(&speed);
    let p = "haas_g76_one_block.nc";
    let height = edit(p, "haas_lathe", "K0.92", "K0.8");
    no_structure_change(&height);
    expect![[r#"
        cycle_parameter_changed | thread_height | 0.0362 | 0.0315
          thread height changed from 0.0362 to 0.0315 at line 13
    "#]]
    .assert_eq(&height);
    let first = edit(p, "haas_lathe", "D0.3", "D0.25");
    no_structure_change(&first);
    expect![[r#"
        cycle_parameter_changed | first_depth_of_cut | 0.0118 | 0.0098
          first depth of cut changed from 0.0118 to 0.0098 at line 13
    "#]]
    .assert_eq(&first);
    let angle = edit(p, "haas_lathe", "F1.5 A60", "F1.5 A55");
    no_structure_change(&angle);
    expect![[r#"
        cycle_parameter_changed | thread_angle | 60° | 55°
          thread angle changed from 60° to 55° at line 13
    "#]]
    .assert_eq(&angle);
}

#[test]
fn siemens_cycle97_lims_and_explicit_passes() {
    let p = "siemens_cycle97.mpf";
    let height = edit(p, "siemens", "4, 2, 1.23, 0.05, 30, 0, 8, 1,", "4, 2, 1.3, 0.05, 30, 0, 8, 1,");
    no_structure_change(&height);
    expect![[r#"
        cycle_parameter_changed | thread_height | 1.23 | 1.3
          thread height changed from 1.23 to 1.3 at line 6
        cycle_parameter_changed | first_depth_of_cut | 0.4172 | 0.4419
          first depth of cut changed from 0.4172 to 0.4419 at line 6
        feature_changed | thread_root_diameter | Ø27.54 | Ø27.4
          thread root diameter changed from Ø27.54 to Ø27.4
        cycle_parameter_changed | CYCLE97 TDEP (profile depth) | 1.23 | 1.3
          CYCLE97 TDEP (profile depth) changed from 1.23 to 1.3 at line 6
    "#]]
    .assert_eq(&height);
    let passes = edit(p, "siemens", "4, 2, 1.23, 0.05, 30, 0, 8, 1,", "4, 2, 1.23, 0.05, 30, 0, 10, 1,");
    no_structure_change(&passes);
    expect![[r#"
        cycle_parameter_changed | first_depth_of_cut | 0.4172 | 0.3731
          first depth of cut changed from 0.4172 to 0.3731 at line 6
        cycle_parameter_changed | CYCLE97 NRC (passes) | 8 | 10
          CYCLE97 NRC (passes) changed from 8 to 10 at line 6
    "#]]
    .assert_eq(&passes);
    let spring = edit(p, "siemens", "4, 2, 1.23, 0.05, 30, 0, 8, 1,", "4, 2, 1.23, 0.05, 30, 0, 8, 2,");
    no_structure_change(&spring);
    expect![[r#"
        cycle_parameter_changed | finishing_passes | 2 | 3
          finishing passes changed from 2 to 3 at line 6
        cycle_parameter_changed | CYCLE97 NID (idle passes) | 1 | 2
          CYCLE97 NID (idle passes) changed from 1 to 2 at line 6
    "#]]
    .assert_eq(&spring);
    let p = "siemens_diamon.mpf";
    let clamp = edit(p, "siemens", "LIMS=2800", "LIMS=2500");
    no_structure_change(&clamp);
    expect![[r#"
        spindle_speed_changed | spindle_clamp | 2800 /min | 2500 /min (also in workingsteps 2, 3)
          spindle clamp changed from 2800 /min to 2500 /min (also in workingsteps 2, 3) at line 5
    "#]]
    .assert_eq(&clamp);
    let speed = edit(p, "siemens", "G96 S220", "G96 S180");
    no_structure_change(&speed);
    expect![[r#"
        spindle_speed_changed | cutting_speed | 220 m/min | 180 m/min (also in workingsteps 2, 3)
          cutting speed changed from 220 m/min to 180 m/min (also in workingsteps 2, 3) at line 5
    "#]]
    .assert_eq(&speed);
    let finish = edit(p, "siemens", "N180 X45 Z-0.5\nN190 Z-25", "N180 X44.9 Z-0.5\nN190 Z-25");
    expect![[r#"
        feature_changed | diameter | Ø45 | Ø44.9 (also in workingstep 3)
          diameter changed from Ø45 to Ø44.9 (also in workingstep 3) at line 19
    "#]]
    .assert_eq(&finish);
    let pass = edit(p, "siemens", "N120 X46\nN130 G1 Z-25\nN140 X52\nN150 G0 Z2\n", "");
    expect![[r#"
        cycle_parameter_changed | roughing_passes | 2 | 1
          roughing passes changed from 2 to 1 at original lines 13, 14, 15 and 1 more
    "#]]
    .assert_eq(&pass);
}

#[test]
fn fusion_explicit_roughing_pass_removed() {
    let pass = edit("fusion_explicit.nc", "fanuc_lathe", "N30 X42.4\nN31 G1 Z-40.9\nN32 X46.4\nN33 G0 Z5.\n", "");
    expect![[r#"
        cycle_parameter_changed | roughing_passes | 3 | 2
          roughing passes changed from 3 to 2 at original lines 28, 29, 30 and 1 more
    "#]]
    .assert_eq(&pass);
}

#[test]
fn linuxcnc_g76_and_g71() {
    let p = "lcnc_g76.ngc";
    let pitch = edit(p, "linuxcnc", "G76 P1.5", "G76 P1.25");
    no_structure_change(&pitch);
    expect![[r#"
        thread_pitch_changed | thread_pitch | 1.5 | 1.25
          thread pitch changed from 1.5 to 1.25 at line 6
    "#]]
    .assert_eq(&pitch);
    let height = edit(p, "linuxcnc", "K1.84", "K1.6");
    no_structure_change(&height);
    expect![[r#"
        cycle_parameter_changed | thread_height | 0.92 | 0.8
          thread height changed from 0.92 to 0.8 at line 6
        feature_changed | thread_root_diameter | Ø18.16 | Ø18.4
          thread root diameter changed from Ø18.16 to Ø18.4 at line 6
    "#]]
    .assert_eq(&height);
    let first = edit(p, "linuxcnc", "J0.4", "J0.3");
    no_structure_change(&first);
    expect![[r#"
        cycle_parameter_changed | first_depth_of_cut | 0.2 | 0.15
          first depth of cut changed from 0.2 to 0.15 at line 6
    "#]]
    .assert_eq(&first);
    let spring = edit(p, "linuxcnc", "H2", "H1");
    no_structure_change(&spring);
    expect![[r#"
        cycle_parameter_changed | finishing_passes | 2 | 1
          finishing passes changed from 2 to 1 at line 6
    "#]]
    .assert_eq(&spring);
    let p = "lcnc_g71_g70.ngc";
    // LinuxCNC's G71 keeps no intent in the plan yet (the increment I, the stock left D):
    // its edits are told as the toolpath the cycle cuts and the word, not in a turner's terms.
    let depth = edit(p, "linuxcnc", "I1.5 D0.3", "I1 D0.3");
    expect![[r#"
        toolpath_changed | toolpath | the 5 cuts at line 13, ending at X10.5 Y0 Z-14.7 | the 8 cuts at line 13, ending at X10 Y0 Z-1.5757 (49.8098 mm longer), in X9…18 Y0…0, at most 0.8888 mm from the original path
          toolpath changed at line 13: the 5 cuts at line 13, ending at X10.5 Y0 Z-14.7 became the 8 cuts at line 13, ending at X10 Y0 Z-1.5757 (49.8098 mm longer), in X9…18 Y0…0, at most 0.8888 mm from the original path
    "#]]
    .assert_eq(&depth);
    let leave = edit(p, "linuxcnc", "I1.5 D0.3", "I1.5 D0.5");
    expect![[r#"
        toolpath_changed | toolpath | the 11 cuts at line 13, ending at X15.3 Y0 | the 11 cuts at line 13, ending at X15.5 Y0 (13.1521 mm shorter), in X9…18 Y0…0, at most 0.2828 mm from the original path
          toolpath changed at line 13: the 11 cuts at line 13, ending at X15.3 Y0 became the 11 cuts at line 13, ending at X15.5 Y0 (13.1521 mm shorter), in X9…18 Y0…0, at most 0.2828 mm from the original path
        cycle_parameter_changed | cycle parameter | D0.3 | D0.5
          cycle parameter changed from D0.3 to D0.5 at line 13
    "#]]
    .assert_eq(&leave);
    let clamp = edit(p, "linuxcnc", "G96 D2500 S180", "G96 D1800 S180");
    no_structure_change(&clamp);
    expect![[r#"
        spindle_speed_changed | spindle_clamp | 2500 /min | 1800 /min (also in workingstep 2)
          spindle clamp changed from 2500 /min to 1800 /min (also in workingstep 2) at line 11
    "#]]
    .assert_eq(&clamp);
    let feed = edit(p, "linuxcnc", "R0.5 F0.25", "R0.5 F0.2");
    no_structure_change(&feed);
    expect![[r#"
        feed_changed | feed | F0.25 mm/rev | F0.2 mm/rev
          feed changed from F0.25 mm/rev to F0.2 mm/rev at line 13
    "#]]
    .assert_eq(&feed);
}

/// Fanuc's two-block `G71`: the second block's `U` (beside P and Q) is the finishing allowance,
/// where the first block's is the depth of cut; its edit is one allowance row, told once.
#[test]
fn fanuc_g71_second_blocks_u_is_the_allowance_told_once() {
    let allowance = edit("fanuc_g71_shaft.nc", "fanuc_lathe", "P10 Q20 U0.4 W0.1", "P10 Q20 U0.8 W0.1");
    no_structure_change(&allowance);
    expect![[r#"
        allowance_changed | finishing_allowance | U0.4 W0.1 | U0.8 W0.1
          finishing allowance changed from U0.4 W0.1 to U0.8 W0.1 at line 11
    "#]]
    .assert_eq(&allowance);
}

/// Two grooves, each plunged by its own tool at its own Z, deepened alike: two features, two
/// changes, each at its own line (not one change "also in" the other workingstep).
#[test]
fn two_grooves_changed_alike_stay_two_changes() {
    let a = "O1002\nG21 G18 G99\nT0101\nG97 S800 M3\nG0 X42. Z-10.\nG1 X30. F0.05\nG0 X42.\nT0202\nG97 S800 M3\nG0 X42. Z-30.\nG1 X30. F0.05\nG0 X42.\nG28 U0 W0\nM30\n";
    let b = a.replace("X30.", "X28.");
    let rows = rows("fanuc_lathe", a, &b);
    assert!(!rows.contains("also in"), "{rows}");
    expect![[r#"
        feature_changed | groove_diameter | Ø30 | Ø28
          groove diameter changed from Ø30 to Ø28 at line 6
        feature_changed | groove_diameter | Ø30 | Ø28
          groove diameter changed from Ø30 to Ø28 at line 11
    "#]]
    .assert_eq(&rows);
}

/// The way the tool leaves the part stops at a reference return: where `G28 U0. W0.` goes only
/// the machine knows (the plan takes it at work zero), so its replacement by a rapid to a
/// change position is told by the return's own statement rows, never as "rapid to Ø0 Z0",
/// a place the program does not state. A back-off before it that changes is still told.
#[test]
fn a_reference_return_replaced_is_told_by_its_statements_not_as_a_way_to_o0_z0() {
    let a = "O1003\nG21 G18 G99\nT0101\nG97 S800 M3\nG0 X40. Z2.\nG1 Z-20. F0.2\nX44.\nG0 Z2.\nG28 U0. W0.\nM30\n";
    let b = a.replace("G28 U0. W0.", "G0 X150. Z100.");
    let replaced = rows("fanuc_lathe", a, &b);
    assert!(!replaced.contains("Ø0 Z0"), "{replaced}");
    expect![[r#"
        return_move_changed | statement | G28 U0 W0 | 
          return move: `G28 U0 W0` removed at original line 9
        statement_changed | statement |  | G0 X150. Z100.
          `G0 X150. Z100.` added at line 9
    "#]]
    .assert_eq(&replaced);
    // The back-off before the return changed: told, up to the return.
    let c = a.replace("G0 Z2.\nG28", "G0 Z5.\nG28");
    let back_off = rows("fanuc_lathe", a, &c);
    assert!(!back_off.contains("Ø0 Z0"), "{back_off}");
    assert!(back_off.contains("retract_changed | retract_path | rapid to Ø44 Z2 | rapid to Ø44 Z5"), "{back_off}");
}

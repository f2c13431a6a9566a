//! A program's machine configuration beside it: LinuxCNC's INI file. What a LinuxCNC machine
//! reads is its interpreter's language plus what its INI adds: codes remapped to subroutines
//! (`[RS274NGC] REMAP=M428 modalgroup=10 ngc=428remap`, the subroutine found on
//! `SUBROUTINE_PATH`, folders relative to the INI's), HAL pins as parameters
//! (`HAL_PIN_VARS`, on by default), and switchable kinematics (`[KINS] KINEMATICS=xyzac-trt-kins
//! sparm=identityfirst`, its type selected by an analog output a `HALCMD = net …
//! motion.analog-out-03 => motion.switchkins-type` wires). This module reads the INI into
//! [`MachineSetup`], the core's data, and puts the subroutine folders in the profile's
//! [`ProgramSource`](crate::interp::ProgramSource); the interpreter reads no file.
//!
//! Which INI: the one given (`--machine-config FILE`), else the INI files of the program's
//! folder, else of the folder above, else the one above that (LinuxCNC's sample layout keeps
//! programs in `demos/` or `nc_files/` under the configuration's folder). Only an INI with an
//! `[RS274NGC]` or `[KINS]` section is a machine's; where one level holds several that add
//! different things, none is taken (the machine is not guessed).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::interp::machine::{Kinematics, KinematicsSwitch, MachineSetup, Remap};
use crate::interp::{Profile, ProgramSource};

/// How many folders above the program's are looked in for its machine's INI.
pub const LEVELS_UP: usize = 2;

/// A machine's configuration read from its INI.
#[derive(Clone, Debug, PartialEq)]
pub struct MachineConfig {
    /// The INI file.
    pub ini: PathBuf,
    /// What it adds to the language.
    pub setup: MachineSetup,
    /// The folders of its `SUBROUTINE_PATH`, absolute or relative to the INI's folder.
    pub subroutine_dirs: Vec<PathBuf>,
}

/// The sections and keys of an INI text, in order: (section, key, value), keys repeated as
/// written (`REMAP`, `HALCMD`), each section's header as (section, "", ""). Comments (`#`, `;` at a line's start) and blank lines are left
/// out.
fn entries(text: &str) -> Vec<(String, String, String)> {
    let mut section = String::new();
    let mut out = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() || line.starts_with(['#', ';']) {
            continue;
        }
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            section = name.trim().to_ascii_uppercase();
            // The section itself, with no key: an empty section still says what the file is.
            out.push((section.clone(), String::new(), String::new()));
            continue;
        }
        if let Some((k, v)) = line.split_once('=') {
            out.push((section.clone(), k.trim().to_ascii_uppercase(), v.trim().to_owned()));
        }
    }
    out
}

/// A REMAP line's code and subroutine: `M428 modalgroup=10 ngc=428remap`. A remap to Python
/// only (no `ngc=`) gives none: the analysis cannot run it.
fn remap(value: &str) -> Option<Remap> {
    let mut words = value.split_whitespace();
    let code = words.next()?;
    let letter = code.chars().next()?.to_ascii_uppercase();
    if !matches!(letter, 'M' | 'G') {
        return None;
    }
    let number: f64 = code[1..].parse().ok()?;
    let sub = words.find_map(|w| w.strip_prefix("ngc=").or_else(|| w.strip_prefix("NGC=")))?;
    let sub = sub.trim_end_matches(".ngc").to_ascii_lowercase();
    Some(Remap { letter, number_x10: (number * 10.0).round() as u32, sub })
}

/// The kinematics types of a switchable kinematics module, by type number, as the LinuxCNC
/// documentation gives them (docs `motion/switchkins.adoc`; the `xyzab_tdr_kins` and
/// `millturn` components' descriptions): the switchkins modules' type 0 is their own model,
/// type 1 identity, type 2 the user's (`sparm=identityfirst` swaps 0 and 1); `xyzab_tdr_kins`
/// is identity first; `millturn` a mill and a lathe model, neither with tool centre point
/// control. A module not listed gives none.
fn kinematics_types(line: &str) -> Option<Vec<Kinematics>> {
    let mut words = line.split_whitespace();
    let module = words.next()?.to_ascii_lowercase();
    let identity_first = words.any(|w| w.eq_ignore_ascii_case("sparm=identityfirst"));
    use Kinematics::{Identity, Other, ToolCentrePoint};
    let mut types = match module.as_str() {
        "xyzac-trt-kins" | "xyzbc-trt-kins" | "5axiskins" => vec![ToolCentrePoint, Identity, Other],
        "genhexkins" | "genserkins" | "pumakins" | "three21kins" | "scarakins" => vec![Other, Identity, Other],
        "xyzab_tdr_kins" => return Some(vec![Identity, ToolCentrePoint]),
        "millturn" => return Some(vec![Other, Other]),
        _ => return None,
    };
    if identity_first {
        types.swap(0, 1);
    }
    Some(types)
}

/// The rotary axes (A, B, C) a kinematics module turns the other way from ISO 841: LinuxCNC's
/// `5axiskins` (the XYZBC bridge mill) its B (the module's notes: "the direction of the tilt
/// axis is the opposite of the conventional axis direction"; its forward kinematics put the
/// tool at the polar angle 180° - B from Z, azimuth C, so B+90 at C0 points the tool from the
/// holder towards +X, where ISO 841's B+90 points it towards -X).
fn reversed_rotary(line: &str) -> [bool; 3] {
    let module = line.split_whitespace().next().unwrap_or_default().to_ascii_lowercase();
    [false, module == "5axiskins", false]
}

/// The analog output a HALCMD line wires to `motion.switchkins-type`:
/// `net :kinstype-select <= motion.analog-out-03 => motion.switchkins-type`.
fn switch_output(halcmd: &str) -> Option<u32> {
    if !halcmd.contains("motion.switchkins-type") {
        return None;
    }
    let at = halcmd.find("motion.analog-out-")? + "motion.analog-out-".len();
    let digits: String = halcmd[at..].chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// Reads the machine configuration of INI text `text`, kept at `ini`. `None` where it is no
/// machine's INI (no `[RS274NGC]` nor `[KINS]` section).
pub fn parse(text: &str, ini: &Path) -> Option<MachineConfig> {
    let entries = entries(text);
    if !entries.iter().any(|(s, ..)| s == "RS274NGC" || s == "KINS") {
        return None;
    }
    let get = |section: &'static str, key: &'static str| {
        entries.iter().filter(move |(s, k, _)| s == section && k == key).map(|(.., v)| v.as_str())
    };
    let dir = ini.parent().unwrap_or(Path::new("."));
    let subroutine_dirs = get("RS274NGC", "SUBROUTINE_PATH")
        .flat_map(|v| v.split(':'))
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .map(|p| if Path::new(p).is_absolute() { PathBuf::from(p) } else { dir.join(p) })
        .collect();
    // On unless the INI turns it off (LinuxCNC INI reference: `HAL_PIN_VARS = 1`, default 1).
    let off = |v: &str| ["0", "false", "no", "off"].iter().any(|o| v.trim().eq_ignore_ascii_case(o));
    let hal_pins = !get("RS274NGC", "HAL_PIN_VARS").any(off);
    let remaps = get("RS274NGC", "REMAP").filter_map(remap).collect();
    let types = get("KINS", "KINEMATICS").next().and_then(kinematics_types);
    let output = entries.iter().filter(|(_, k, _)| k == "HALCMD").find_map(|(.., v)| switch_output(v));
    let kinematics = match (types, output) {
        // M67 and M68 set an analog output (LinuxCNC G-code reference, M67/M68).
        (Some(types), Some(output)) => Some(KinematicsSwitch { codes: vec![('M', 670), ('M', 680)], output, types }),
        _ => None,
    };
    let reversed_rotary = get("KINS", "KINEMATICS").next().map_or([false; 3], reversed_rotary);
    let source = ini.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let setup = MachineSetup { remaps, hal_pins, kinematics, reversed_rotary, source };
    Some(MachineConfig { ini: ini.to_path_buf(), setup, subroutine_dirs })
}

/// Reads the INI file at `ini`.
pub fn read(ini: &Path) -> anyhow::Result<MachineConfig> {
    let text = std::fs::read(ini).map_err(|e| anyhow::anyhow!("cannot read {}: {e}", ini.display()))?;
    parse(&String::from_utf8_lossy(&text), ini)
        .ok_or_else(|| anyhow::anyhow!("{} is no machine configuration: it has no [RS274NGC] or [KINS] section", ini.display()))
}

/// The machine configuration of the program at `program`: the INI files of its folder or of
/// the [`LEVELS_UP`] folders above, the nearest level that has one; `None` where none is found
/// or one level's INIs add different things.
pub fn find(program: &Path) -> Option<MachineConfig> {
    find_under(program, None)
}

/// [`find`] for a program of a watched folder `root`: no INI above the folder is read, and a
/// `SUBROUTINE_PATH` folder outside it is left out. A share's users write what is in it; the
/// server's other files are not theirs to name.
pub fn find_within(program: &Path, root: &Path) -> Option<MachineConfig> {
    let root = std::path::absolute(root).unwrap_or_else(|_| root.to_path_buf());
    let mut config = find_under(program, Some(&root))?;
    config.subroutine_dirs.retain(|d| lexical(d).starts_with(&root));
    Some(config)
}

/// `path` made absolute with its `.` and `..` resolved by name (LinuxCNC's configurations name
/// their subroutine folders `../../nc_files/remap_lib`).
fn lexical(path: &Path) -> PathBuf {
    let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            std::path::Component::ParentDir => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

fn find_under(program: &Path, root: Option<&Path>) -> Option<MachineConfig> {
    let dir = program.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    // Absolute, so that the folders above a relative `nc_files/part.ngc` are reached (popping
    // `nc_files` leaves an empty path, which names no folder).
    let mut dir = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
    for _ in 0..=LEVELS_UP {
        if root.is_some_and(|r| !dir.starts_with(r)) {
            break;
        }
        let mut inis: Vec<PathBuf> = std::fs::read_dir(&dir)
            .into_iter()
            .flatten()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("ini")) && p.is_file())
            .collect();
        inis.sort();
        let found: Vec<MachineConfig> = inis.iter().filter_map(|p| read(p).ok()).collect();
        if let Some(first) = found.first() {
            let same = found.iter().all(|c| c.setup.remaps == first.setup.remaps && c.setup.kinematics == first.setup.kinematics);
            return same.then(|| first.clone());
        }
        if !dir.pop() {
            break;
        }
    }
    None
}

/// `profile` with machine configuration `config`: its setup, and its subroutine folders after
/// the profile's own program source.
pub fn apply(profile: &Profile, config: &MachineConfig, max_bytes: u64) -> Profile {
    let mut p = profile.clone();
    p.machine = Arc::new(config.setup.clone());
    let mut sources: Vec<Arc<dyn ProgramSource + Send + Sync>> = p.programs.iter().cloned().collect();
    for dir in &config.subroutine_dirs {
        sources.push(Arc::new(crate::config::DirPrograms { dir: dir.clone(), max_bytes, subfolders: false }));
    }
    p.programs = Some(Arc::new(crate::config::FirstFound(sources)));
    p
}

/// `profile` with the machine configuration given (`explicit`) or found for `program`
/// ([`find`]); unchanged where there is none.
pub fn for_program(profile: &Profile, program: &Path, explicit: Option<&Path>, max_bytes: u64) -> anyhow::Result<Profile> {
    let config = match explicit {
        Some(ini) => Some(read(ini)?),
        None => find(program),
    };
    Ok(match config {
        Some(c) => apply(profile, &c, max_bytes),
        None => profile.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const INI: &str = "[RS274NGC]\nSUBROUTINE_PATH = ./remap_subs:/abs\n   HAL_PIN_VARS = 1\n  REMAP = M428  modalgroup=10  ngc=428remap\nREMAP=M429 modalgroup=10 python=foo\n[KINS]\n# comment\nKINEMATICS = xyzac-trt-kins sparm=identityfirst\n[HAL]\nHALCMD = net :kinstype-select <= motion.analog-out-03 => motion.switchkins-type\n";

    /// The daemon reads no INI above the watched folder, and no subroutine folder outside it,
    /// however the INI names it; the CLI looks up to two folders above the program.
    #[test]
    fn a_watched_folder_confines_the_lookup() {
        let tmp = tempfile::tempdir().unwrap();
        let share = tmp.path().join("share");
        std::fs::create_dir_all(share.join("cfg/nc")).unwrap();
        std::fs::create_dir_all(share.join("cfg/subs")).unwrap();
        let ini = "[RS274NGC]\nSUBROUTINE_PATH = ./subs:../../outside:/etc:../cfg/subs\nREMAP = M428 modalgroup=10 ngc=428remap\n";
        std::fs::write(share.join("cfg/m.ini"), ini).unwrap();
        std::fs::write(tmp.path().join("above.ini"), ini).unwrap();
        let program = share.join("cfg/nc/part.ngc");
        let found = find_within(&program, &share).unwrap();
        assert_eq!(found.ini, share.join("cfg/m.ini"));
        let dirs: Vec<PathBuf> = found.subroutine_dirs.iter().map(|d| lexical(d)).collect();
        assert_eq!(dirs, vec![share.join("cfg/subs"), share.join("cfg/subs")]);
        // A program at the share's top: the INI above the share is not read.
        assert!(find_within(&share.join("part.ngc"), &share).is_none());
        assert!(find(&share.join("part.ngc")).is_some());
    }

    #[test]
    fn reads_remaps_pins_and_the_kinematics_switch() {
        let c = parse(INI, Path::new("/m/xyzac-trt.ini")).unwrap();
        assert_eq!(c.subroutine_dirs, vec![PathBuf::from("/m/./remap_subs"), PathBuf::from("/abs")]);
        assert!(c.setup.hal_pins);
        assert_eq!(c.setup.remaps, vec![Remap { letter: 'M', number_x10: 4280, sub: "428remap".into() }]);
        let k = c.setup.kinematics.unwrap();
        assert_eq!(k.output, 3);
        // identityfirst: type 0 identity, type 1 the 5-axis model.
        assert_eq!(k.selects('M', 680, 3.0, 1.0), Some(Kinematics::ToolCentrePoint));
        assert_eq!(k.selects('M', 680, 3.0, 0.0), Some(Kinematics::Identity));
        assert_eq!(k.selects('M', 680, 2.0, 1.0), None);
        assert_eq!(k.selects('M', 650, 3.0, 1.0), None);
    }

    #[test]
    fn hal_pins_are_on_unless_turned_off() {
        assert!(parse("[RS274NGC]\n", Path::new("a.ini")).unwrap().setup.hal_pins);
        assert!(!parse("[RS274NGC]\nHAL_PIN_VARS = 0\n", Path::new("a.ini")).unwrap().setup.hal_pins);
    }

    #[test]
    fn an_ini_without_a_machine_section_is_none() {
        assert!(parse("[.ShellClassInfo]\nIconResource=x\n", Path::new("desktop.ini")).is_none());
    }
}

//! The program's machine, as data: what a machine's own configuration adds to the language
//! its control reads. The shell reads the configuration (`machine_config`: LinuxCNC's INI
//! beside the program) and hands the interpreter this table; the core reads no file.
//!
//! - **Remaps** — LinuxCNC `[RS274NGC] REMAP=M428 modalgroup=10 ngc=428remap`: the code, which
//!   the language lacks, is a call of the O-word subroutine `428remap`, found on the machine's
//!   `SUBROUTINE_PATH` (the shell puts those folders in the profile's `ProgramSource`). The
//!   call runs after the block's other words, with no arguments (an `argspec` is not read).
//! - **HAL pins as parameters** — `HAL_PIN_VARS=1`: `#<_hal[pin]>` reads a pin of the
//!   running machine; the analysis has no machine, so the value is unknown, and the pin is
//!   taken to exist.
//! - **Kinematics switch** — LinuxCNC switchable kinematics (`motion.switchkins-type`, driven
//!   from an analog output `M68 E3 Q1` by a HAL net): which analog output selects the type,
//!   and which types keep the tool centre point on the part (a 5-axis kinematics module) and
//!   which move the joints as the axes (identity). Writing a type of the first kind turns tool
//!   centre point control on; of the second, off.

/// What a machine's configuration adds to its control's language (empty: nothing).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MachineSetup {
    /// Codes made calls of a subroutine, in the configuration's order.
    pub remaps: Vec<Remap>,
    /// `#<_hal[...]>` reads a pin: unknown, existing.
    pub hal_pins: bool,
    /// The switch of the machine's kinematics, where it has one.
    pub kinematics: Option<KinematicsSwitch>,
    /// The rotary axes (A, B, C) whose positive turn tilts the tool the other way from ISO
    /// 841 on this machine's kinematics (LinuxCNC `5axiskins`: its B, "the direction of the
    /// tilt axis is the opposite of the conventional axis direction", its model putting the
    /// tool at the polar angle 180° - B): the tool axis the rotary axes give is read so.
    pub reversed_rotary: [bool; 3],
    /// Where the setup was read (the INI's name), for the notes that name it.
    pub source: String,
}

/// A code the configuration makes a call of a subroutine.
#[derive(Clone, Debug, PartialEq)]
pub struct Remap {
    /// The code's letter, upper case (`M`, `G`).
    pub letter: char,
    /// The code's number times ten (`M428` → 4280, `G88.1` → 881).
    pub number_x10: u32,
    /// The subroutine's name (`428remap` for `o<428remap> sub`).
    pub sub: String,
}

/// Switchable kinematics, selected by an analog output.
#[derive(Clone, Debug, PartialEq)]
pub struct KinematicsSwitch {
    /// The codes that set an analog output (LinuxCNC `M67`, `M68`), letter and number.
    pub codes: Vec<(char, u32)>,
    /// The analog output (E word) wired to the kinematics type.
    pub output: u32,
    /// What each type is, by type number.
    pub types: Vec<Kinematics>,
}

/// What one kinematics type does to X Y Z and the rotary axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kinematics {
    /// Joints are the axes: the rotary axes turn without the tool tip following them.
    Identity,
    /// A 5-axis model: X Y Z are the tool tip's on the part as the rotary axes turn (tool
    /// centre point control).
    ToolCentrePoint,
    /// Some other model (a mill-turn's mill or lathe mode): no tool centre point control.
    Other,
}

impl MachineSetup {
    /// The subroutine code `letter` `number_x10` is remapped to, if any.
    pub fn remap(&self, letter: char, number_x10: u32) -> Option<&str> {
        let letter = letter.to_ascii_uppercase();
        self.remaps.iter().find(|r| r.letter == letter && r.number_x10 == number_x10).map(|r| r.sub.as_str())
    }

    /// Whether nothing is set.
    pub fn is_empty(&self) -> bool {
        self.remaps.is_empty() && !self.hal_pins && self.kinematics.is_none() && self.reversed_rotary == [false; 3]
    }
}

impl KinematicsSwitch {
    /// What writing `value` on analog output `output` with code `letter` `number` does to the
    /// kinematics: `None` where that is not the switch (another output or code), else the
    /// type's kind (`Other` for a type the table lacks).
    pub fn selects(&self, letter: char, number: u32, output: f64, value: f64) -> Option<Kinematics> {
        let code = (letter.to_ascii_uppercase(), number);
        if !self.codes.contains(&code) || output.fract() != 0.0 || output < 0.0 || output as u32 != self.output {
            return None;
        }
        // The pin is floating point, truncated to an integer (LinuxCNC switchkins).
        let t = value.trunc();
        Some(if t >= 0.0 { self.types.get(t as usize).copied().unwrap_or(Kinematics::Other) } else { Kinematics::Other })
    }
}

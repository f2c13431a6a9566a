//! FreeCAD's CAM (Path) tool files, read: a tool bit (`.fctb`) and a tool library (`.fctl`).
//!
//! The formats, as the files FreeCAD ships (`src/Mod/CAM/Tools/`, formerly `src/Mod/Path/Tools/`)
//! show them:
//! - a **tool bit** is JSON: `version` (2), `name` (what the planner calls it), `shape` (the
//!   template file, `endmill.fcstd`, `bullnose.fcstd`, `drill.fcstd`…), in newer files
//!   `shape-type` (`Bullnose`), `parameter` (the shape's dimensions as quantities with their
//!   unit: `"Diameter": "6.0000 mm"`, `"TipAngle": "119.0000 °"`, inch files `"0.2500 in"`) and
//!   `attribute` (further properties, in some files `Flutes`, `Chipload`, `Material`). The
//!   corner radius is `CornerRadius` in newer bull-nose bits; older ones give `FlatRadius`,
//!   the radius of the flat bottom, so that the corner radius is half the diameter less it.
//!   Flutes are a plain number or a quantity without unit, under `parameter` or `attribute`.
//! - a **tool library** is JSON: `version` (1) and `tools`, a list of `{"nr": 1, "path":
//!   "5mm_Endmill.fctb"}`: the tool number the post writes and the bit's file, relative to the
//!   library's folder or to the `Bit` folder beside it (FreeCAD keeps `Tools/Library/` and
//!   `Tools/Bit/` side by side), or absolute.
//!
//! Pure: the shell reads the files and hands their text in.

use serde_json::Value;

use super::library::LibraryTool;

/// A quantity's value in millimetres (`"6.0000 mm"`, `"0.25 in"`, `"1 cm"`, a bare number as
/// millimetres); `None` for another unit (an angle) or no number.
pub fn length_mm(v: &Value) -> Option<f64> {
    if let Some(n) = v.as_f64() {
        return Some(n);
    }
    let s = v.as_str()?.trim();
    let split = s.find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'))).unwrap_or(s.len());
    let n: f64 = s[..split].trim().parse().ok()?;
    let scale = match s[split..].trim() {
        "" | "mm" => 1.0,
        "cm" => 10.0,
        "m" => 1000.0,
        "in" | "\"" | "inch" => 25.4,
        "ft" | "'" => 304.8,
        _ => return None,
    };
    Some(n * scale)
}

/// A count (`2`, `"2"`, `"2.0000"`).
fn count(v: &Value) -> Option<u32> {
    let n = v.as_f64().or_else(|| v.as_str()?.trim().parse().ok())?;
    (n >= 1.0 && n.fract() == 0.0 && n < 1000.0).then_some(n as u32)
}

/// A tool bit's JSON (`.fctb`), as a library tool without a number (a library gives it one).
pub fn bit(text: &str) -> Result<LibraryTool, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let param = v.get("parameter").and_then(Value::as_object).ok_or("no `parameter` object: not a FreeCAD tool bit")?;
    let attr = v.get("attribute").and_then(Value::as_object);
    let get = |k: &str| param.get(k).or_else(|| attr.and_then(|a| a.get(k)));
    let diameter = get("Diameter").and_then(length_mm);
    let corner_radius = get("CornerRadius")
        .and_then(length_mm)
        .or_else(|| Some(diameter? / 2.0 - get("FlatRadius").and_then(length_mm)?).filter(|r| *r >= 0.0));
    let shape = v.get("shape").and_then(Value::as_str).unwrap_or("");
    let kind = v
        .get("shape-type")
        .and_then(Value::as_str)
        .map(str::to_owned)
        .unwrap_or_else(|| shape.rsplit(['/', '\\']).next().unwrap_or(shape).trim_end_matches(".fcstd").to_owned());
    Ok(LibraryTool {
        number: None,
        description: v.get("name").and_then(Value::as_str).unwrap_or("").trim().to_owned(),
        kind,
        inch: false,
        diameter,
        flutes: get("Flutes").and_then(count),
        corner_radius,
        presets: Vec::new(),
        raw: Value::Null,
    })
}

/// A tool library's JSON (`.fctl`): each tool's number and its bit's path as written.
pub fn library(text: &str) -> Result<Vec<(u32, String)>, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let tools = v.get("tools").and_then(Value::as_array).ok_or("no `tools` list: not a FreeCAD tool library")?;
    let mut out = Vec::new();
    for t in tools {
        let nr = t.get("nr").and_then(|n| n.as_u64().or_else(|| n.as_str()?.trim().parse().ok()));
        let path = t.get("path").and_then(Value::as_str);
        match (nr, path) {
            (Some(nr), Some(p)) if nr <= u64::from(u32::MAX) => out.push((nr as u32, p.to_owned())),
            _ => return Err(format!("a tool entry without a number and a path: {t}")),
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    // The shapes of FreeCAD's own bits (LGPL-2.1, `src/Mod/CAM/Tools/Bit/`), written here by hand.
    #[test]
    fn a_bull_nose_bit_gives_its_corner_radius_in_either_form() {
        let newer = r#"{"version": 2, "name": "6 mm Bull Nose", "shape": "bullnose.fcstd", "shape-type": "Bullnose",
            "parameter": {"CuttingEdgeHeight": "40.0000 mm", "Diameter": "6.0000 mm", "CornerRadius": "1.5000 mm",
            "Length": "50.0000 mm", "ShankDiameter": "3.0000 mm"}, "attribute": {}}"#;
        let older = r#"{"version": 2, "name": "6 mm Bull Nose", "shape": "bullnose.fcstd",
            "parameter": {"Diameter": "6.0000 mm", "FlatRadius": "1.5000 mm"}, "attribute": {}}"#;
        for text in [newer, older] {
            let t = super::bit(text).unwrap();
            assert_eq!((t.description.as_str(), t.diameter, t.corner_radius), ("6 mm Bull Nose", Some(6.0), Some(1.5)));
        }
        assert_eq!(super::bit(newer).unwrap().kind, "Bullnose");
        assert_eq!(super::bit(older).unwrap().kind, "bullnose");
    }

    #[test]
    fn quantities_in_inches_and_flutes_as_attributes() {
        let t = super::bit(
            r#"{"name": "1/4 in 2FL", "shape": "endmill.fcstd", "parameter": {"Diameter": "0.2500 in"},
            "attribute": {"Flutes": 2, "Material": "Carbide"}}"#,
        )
        .unwrap();
        assert_eq!((t.diameter, t.flutes, t.corner_radius), (Some(6.35), Some(2), None));
        assert_eq!(super::length_mm(&json!("119.0000 °")), None, "an angle is no length");
        assert_eq!(super::length_mm(&json!("5 mm")), Some(5.0));
        assert!(super::bit(r#"{"data": []}"#).is_err());
    }

    #[test]
    fn a_library_numbers_its_bits() {
        let l =
            super::library(r#"{"tools": [{"nr": 1, "path": "5mm_Endmill.fctb"}, {"nr": 4, "path": "6mm_Bullnose.fctb"}], "version": 1}"#);
        assert_eq!(l.unwrap(), [(1, "5mm_Endmill.fctb".to_owned()), (4, "6mm_Bullnose.fctb".to_owned())]);
        assert!(super::library(r#"{"tools": [{"path": "x.fctb"}]}"#).is_err());
    }
}

//! Numbers in messages: short whatever the value. Rust prints an `f64` with every digit of its
//! decimal expansion (`1e300` as 301 digits), so values from files are formatted here before
//! they go into an error line.

/// `v` in at most 17 significant digits: plain for 1e-4 ≤ |v| < 1e7 (`0.5`, `-650`, `2.25`),
/// else in exponent form (`1e300`, `1.5e-9`); `NaN`, `inf`, `-inf` as such.
pub fn num(v: f64) -> String {
    if !v.is_finite() || v == 0.0 || (1e-4..1e7).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `[a, b, c]` with every value through [`num`].
pub fn nums(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", ")
    )
}

/// Rewrites every run of more than 24 digits (with its sign, decimal point and fraction) as
/// [`num`] would print it: the last guard of the one-line error contract against a value
/// formatted without [`num`] somewhere.
pub fn compact_numbers(line: &str) -> String {
    let bytes = line.as_bytes();
    let mut out = String::with_capacity(line.len());
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        let mut j = i;
        if bytes[j] == b'-' && j + 1 < bytes.len() && bytes[j + 1].is_ascii_digit() {
            j += 1;
        }
        let digits_from = j;
        while j < bytes.len() && (bytes[j].is_ascii_digit() || bytes[j] == b'.') {
            j += 1;
        }
        let token = &line[start..j];
        let digits = line[digits_from..j]
            .bytes()
            .filter(u8::is_ascii_digit)
            .count();
        match token.parse::<f64>() {
            Ok(v) if digits > 24 => {
                out.push_str(&num(v));
                i = j;
            }
            _ => {
                let c = line[i..].chars().next().unwrap_or(' ');
                out.push(c);
                i += c.len_utf8();
            }
        }
    }
    out
}

/// A unit as written for people: `um` → `µm`, `um_per_m` → `µm/m`, `um_s2_per_m` → `µm·s²/m`
/// (the JSON's unit names, docs/commands.md); others as they are.
pub fn unit_symbol(unit: &str) -> &str {
    match unit {
        "um" => "µm",
        "um_per_m" => "µm/m",
        "um_s2_per_m" => "µm·s²/m",
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_stay_short() {
        assert_eq!(num(0.5), "0.5");
        assert_eq!(num(-650.0), "-650");
        assert_eq!(num(1e300), "1e300");
        assert_eq!(num(-1.5e-9), "-1.5e-9");
        assert_eq!(num(f64::NAN), "NaN");
        assert_eq!(num(f64::MAX).len(), "1.7976931348623157e308".len());
        let long = format!("x: {} must be > 0, and {:.1}", 1e300, -2.5e200);
        let short = compact_numbers(&long);
        assert_eq!(short, "x: 1e300 must be > 0, and -2.5e200");
        assert_eq!(
            compact_numbers("line 42, 3.14 mm, é 7"),
            "line 42, 3.14 mm, é 7"
        );
    }
}

//! Names shared along the whole data path: machine axes, circle planes, directions and the
//! EIJ parameters (ISO 230-1 notation with the acceleration dot left out).

use std::collections::{btree_map, BTreeMap};
use std::fmt;
use std::str::FromStr;

/// A linear machine axis; positive is the tool moving relative to the workpiece (ISO 841).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Axis {
    /// X axis.
    X,
    /// Y axis.
    Y,
    /// Z axis.
    Z,
}

impl Axis {
    /// All three axes in the order x, y, z.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// Index 0, 1, 2 for x, y, z (also the machine-coordinate component).
    pub fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name as used in file columns and on the command line (`x`, `y`, `z`).
    pub fn name(self) -> &'static str {
        ["x", "y", "z"][self.index()]
    }

    /// Upper-case letter as used in parameter names (`X`, `Y`, `Z`).
    pub fn letter(self) -> char {
        ['X', 'Y', 'Z'][self.index()]
    }

    /// Unit vector of the axis in machine coordinates.
    pub fn unit(self) -> [f64; 3] {
        let mut e = [0.0; 3];
        e[self.index()] = 1.0;
        e
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Axis {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "x" => Ok(Axis::X),
            "y" => Ok(Axis::Y),
            "z" => Ok(Axis::Z),
            _ => Err(format!("unknown axis '{s}' (expected x, y or z)")),
        }
    }
}

/// A circle-test plane. In plane `ab` the set circle is a = r·cos(ωt), b = r·sin(ωt)
/// (paper eq. 3–4); `zx` thus has z = r·cos, x = r·sin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Plane {
    /// a = x, b = y, normal z.
    Xy,
    /// a = y, b = z, normal x.
    Yz,
    /// a = z, b = x, normal y.
    Zx,
}

impl Plane {
    /// All three planes.
    pub const ALL: [Plane; 3] = [Plane::Xy, Plane::Yz, Plane::Zx];

    /// The in-plane axes (a, b) in the order of eq. 3–4.
    pub fn axes(self) -> (Axis, Axis) {
        match self {
            Plane::Xy => (Axis::X, Axis::Y),
            Plane::Yz => (Axis::Y, Axis::Z),
            Plane::Zx => (Axis::Z, Axis::X),
        }
    }

    /// The axis normal to the plane.
    pub fn normal(self) -> Axis {
        match self {
            Plane::Xy => Axis::Z,
            Plane::Yz => Axis::X,
            Plane::Zx => Axis::Y,
        }
    }

    /// Lower-case name (`xy`, `yz`, `zx`).
    pub fn name(self) -> &'static str {
        match self {
            Plane::Xy => "xy",
            Plane::Yz => "yz",
            Plane::Zx => "zx",
        }
    }

    /// The six EIJ of the plane: the two in-talk parameters E_aa, E_bb, then the cross-talk
    /// E_ba, E_ab, E_ka, E_kb (k the normal axis). For `zx` this is EZZ, EXX, EXZ, EZX, EYZ, EYX.
    pub fn parameters(self) -> [Eij; 6] {
        let (a, b) = self.axes();
        let k = self.normal();
        [
            Eij::new(a, a),
            Eij::new(b, b),
            Eij::new(b, a),
            Eij::new(a, b),
            Eij::new(k, a),
            Eij::new(k, b),
        ]
    }
}

impl fmt::Display for Plane {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Plane {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "xy" => Ok(Plane::Xy),
            "yz" => Ok(Plane::Yz),
            "zx" => Ok(Plane::Zx),
            _ => Err(format!("unknown plane '{s}' (expected xy, yz or zx)")),
        }
    }
}

/// Sense of rotation: `ccw` is ω > 0 in a = r·cos(ωt), b = r·sin(ωt), `cw` is ω < 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Direction {
    /// Clockwise, ω < 0.
    Cw,
    /// Counter-clockwise, ω > 0.
    Ccw,
}

impl Direction {
    /// Both directions.
    pub const ALL: [Direction; 2] = [Direction::Cw, Direction::Ccw];

    /// Lower-case name (`cw`, `ccw`).
    pub fn name(self) -> &'static str {
        match self {
            Direction::Cw => "cw",
            Direction::Ccw => "ccw",
        }
    }

    /// The direction of a signed angular speed ω: ccw for ω > 0, else cw.
    pub(crate) fn of_omega(omega_rad_s: f64) -> Direction {
        if omega_rad_s > 0.0 {
            Direction::Ccw
        } else {
            Direction::Cw
        }
    }

    /// Sign of ω: +1 for ccw, −1 for cw.
    pub fn sign(self) -> f64 {
        match self {
            Direction::Cw => -1.0,
            Direction::Ccw => 1.0,
        }
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Direction {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "cw" => Ok(Direction::Cw),
            "ccw" => Ok(Direction::Ccw),
            _ => Err(format!("unknown direction '{s}' (expected cw or ccw)")),
        }
    }
}

/// An acceleration correlated position error parameter `EIJ`: deviation of the TCP in
/// direction `deviation` per set acceleration of axis `accelerated`, in µm·s²/m.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Eij {
    /// I: the direction of the deviation.
    pub deviation: Axis,
    /// J: the accelerated axis.
    pub accelerated: Axis,
}

impl Eij {
    /// The parameter E_{deviation, accelerated}.
    pub fn new(deviation: Axis, accelerated: Axis) -> Self {
        Eij {
            deviation,
            accelerated,
        }
    }

    /// In-talk (I = J) rather than cross-talk.
    pub fn is_in_talk(self) -> bool {
        self.deviation == self.accelerated
    }

    /// Name as in files and JSON keys, e.g. `EXZ`.
    pub fn name(self) -> String {
        format!("E{}{}", self.deviation.letter(), self.accelerated.letter())
    }
}

impl fmt::Display for Eij {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

impl FromStr for Eij {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || format!("unknown parameter '{s}' (expected EIJ with I, J in X, Y, Z)");
        let up = s.to_ascii_uppercase();
        let mut chars = up.chars();
        if chars.next() != Some('E') || up.len() != 3 {
            return Err(bad());
        }
        let i = chars
            .next()
            .ok_or_else(bad)?
            .to_string()
            .parse()
            .map_err(|_| bad())?;
        let j = chars
            .next()
            .ok_or_else(bad)?
            .to_string()
            .parse()
            .map_err(|_| bad())?;
        Ok(Eij::new(i, j))
    }
}

/// EIJ values alone, by parameter, µm·s²/m: what a simulation predicts, or one route of an
/// evaluation; measured values travel with their standard errors as [`EijEstimates`].
pub type EijMap = BTreeMap<Eij, f64>;

/// A value estimated from data, with its standard error (in the value's unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// The estimate.
    pub value: f64,
    /// Its standard error.
    pub std_err: f64,
}

/// EIJ estimated from data, each with its standard error, by parameter: what an evaluation of a
/// circle test or a move gives, and what an identification fits the model to. µm·s²/m (the
/// geometric terms of a pooled evaluation: µm per mm of set position).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EijEstimates(BTreeMap<Eij, Estimate>);

impl EijEstimates {
    /// No estimates yet.
    pub fn new() -> Self {
        EijEstimates(BTreeMap::new())
    }

    /// Values that share one standard error (e.g. simulated EIJ taken as measured with a
    /// given uncertainty).
    pub fn with_std_err(values: impl IntoIterator<Item = (Eij, f64)>, std_err: f64) -> Self {
        values
            .into_iter()
            .map(|(p, value)| (p, Estimate { value, std_err }))
            .collect()
    }

    /// Sets the estimate of `eij` (replacing an earlier one).
    pub fn insert(&mut self, eij: Eij, value: f64, std_err: f64) {
        self.0.insert(eij, Estimate { value, std_err });
    }

    /// The estimate of `eij`, if there is one.
    pub fn get(&self, eij: &Eij) -> Option<&Estimate> {
        self.0.get(eij)
    }

    /// The value of `eij`, if estimated.
    pub fn value(&self, eij: &Eij) -> Option<f64> {
        self.0.get(eij).map(|e| e.value)
    }

    /// The standard error of `eij`, if estimated.
    pub fn std_err(&self, eij: &Eij) -> Option<f64> {
        self.0.get(eij).map(|e| e.std_err)
    }

    /// Whether `eij` is estimated.
    pub fn contains(&self, eij: &Eij) -> bool {
        self.0.contains_key(eij)
    }

    /// How many EIJ are estimated.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether none is.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The estimated EIJ, in order (`EXX`, `EXY`, … `EZZ`).
    pub fn keys(&self) -> impl Iterator<Item = Eij> + '_ {
        self.0.keys().copied()
    }

    /// Every EIJ with its estimate, in order.
    pub fn iter(&self) -> btree_map::Iter<'_, Eij, Estimate> {
        self.0.iter()
    }

    /// Every EIJ with its estimate to change, in order.
    pub fn iter_mut(&mut self) -> btree_map::IterMut<'_, Eij, Estimate> {
        self.0.iter_mut()
    }

    /// The values alone (for tables and JSON objects of values).
    pub fn value_map(&self) -> EijMap {
        self.0.iter().map(|(p, e)| (*p, e.value)).collect()
    }

    /// The standard errors alone.
    pub(crate) fn std_err_map(&self) -> EijMap {
        self.0.iter().map(|(p, e)| (*p, e.std_err)).collect()
    }
}

impl std::ops::Index<&Eij> for EijEstimates {
    type Output = Estimate;
    /// The estimate of an EIJ that must be there (panics otherwise, like a map's index).
    fn index(&self, eij: &Eij) -> &Estimate {
        &self.0[eij]
    }
}

impl FromIterator<(Eij, Estimate)> for EijEstimates {
    fn from_iter<T: IntoIterator<Item = (Eij, Estimate)>>(iter: T) -> Self {
        EijEstimates(iter.into_iter().collect())
    }
}

impl<'a> IntoIterator for &'a EijEstimates {
    type Item = (&'a Eij, &'a Estimate);
    type IntoIter = btree_map::Iter<'a, Eij, Estimate>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

/// Serde as the names of files and JSON keys (`x`, `zx`, `ccw`, `EXZ`), through `Display` and
/// `FromStr`, so that a file is read back with the very names it was written with.
macro_rules! serde_by_name {
    ($($t:ty),*) => {$(
        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.collect_str(self)
            }
        }

        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = <std::borrow::Cow<'de, str>>::deserialize(d)?;
                text.parse().map_err(serde::de::Error::custom)
            }
        }
    )*};
}

serde_by_name!(Axis, Plane, Direction, Eij);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zx_parameters_follow_the_contract_order() {
        let names: Vec<String> = Plane::Zx.parameters().iter().map(|p| p.name()).collect();
        assert_eq!(names, ["EZZ", "EXX", "EXZ", "EZX", "EYZ", "EYX"]);
    }

    #[test]
    fn estimates_keep_value_and_standard_error_together() {
        let (exz, ezz) = ("EXZ".parse().unwrap(), "EZZ".parse().unwrap());
        let mut e = EijEstimates::with_std_err([(ezz, -0.34), (exz, -0.28)], 0.02);
        e.insert(exz, -0.30, 0.05);
        assert_eq!(e.len(), 2);
        assert_eq!(
            e[&exz],
            Estimate {
                value: -0.30,
                std_err: 0.05
            }
        );
        assert_eq!((e.value(&ezz), e.std_err(&ezz)), (Some(-0.34), Some(0.02)));
        assert_eq!(e.keys().collect::<Vec<_>>(), [exz, ezz]);
        assert_eq!(e.value_map(), EijMap::from([(exz, -0.30), (ezz, -0.34)]));
        assert_eq!(e.std_err_map(), EijMap::from([(exz, 0.05), (ezz, 0.02)]));
        assert!(!e.contains(&"EXX".parse().unwrap()));
    }

    #[test]
    fn names_round_trip() {
        for p in Plane::ALL {
            assert_eq!(p.name().parse::<Plane>().unwrap(), p);
            for e in p.parameters() {
                assert_eq!(e.name().parse::<Eij>().unwrap(), e);
            }
        }
        assert!("EQX".parse::<Eij>().is_err());
        assert!("EXXX".parse::<Eij>().is_err());
    }
}

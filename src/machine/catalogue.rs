//! Carriage stiffness catalogue (bundled `machines/catalogue/carriages.toml` plus user files).

use super::raw::RawCatalogue;
use super::MachineError;
use std::collections::BTreeMap;

/// The catalogue bundled with eij (`machines/catalogue/carriages.toml`).
pub(crate) const BUNDLED: &str = include_str!("../../machines/catalogue/carriages.toml");

/// Stiffness data of one carriage type.
#[derive(Debug, Clone, PartialEq)]
pub struct CarriageData {
    /// Catalogue id.
    pub id: String,
    /// Compressive (radial) stiffness, N/m.
    pub radial_n_per_m: f64,
    /// Tensile (reverse-radial) stiffness, N/m.
    pub reverse_radial_n_per_m: f64,
    /// Lateral stiffness, N/m.
    pub lateral_n_per_m: f64,
    /// Names of the values that are estimates.
    pub estimated: Vec<String>,
    /// Published source.
    pub source: String,
}

impl CarriageData {
    /// Normal stiffness of the linearised, preloaded carriage: the mean of the compressive and
    /// tensile values, N/m.
    pub fn normal_n_per_m(&self) -> f64 {
        0.5 * (self.radial_n_per_m + self.reverse_radial_n_per_m)
    }
}

/// A set of catalogue entries by id.
#[derive(Debug, Clone, Default)]
pub struct Catalogue {
    entries: BTreeMap<String, CarriageData>,
    /// The file each entry came from.
    files: BTreeMap<String, String>,
}

impl Catalogue {
    /// The bundled catalogue.
    pub fn bundled() -> Result<Self, MachineError> {
        let mut c = Catalogue::default();
        c.add_toml(BUNDLED, "machines/catalogue/carriages.toml")?;
        Ok(c)
    }

    /// Adds the entries of a catalogue file's text; `file` names it in errors.
    pub(crate) fn add_toml(&mut self, text: &str, file: &str) -> Result<(), MachineError> {
        let raw: RawCatalogue =
            toml::from_str(text).map_err(|e| MachineError::toml(file, text, &e))?;
        for (i, c) in raw.carriages.into_iter().enumerate() {
            let key = |k: &str| format!("carriage[{i}] ({}).{k}", c.id);
            for (k, v) in [
                ("radial_n_per_um", c.radial_n_per_um),
                ("reverse_radial_n_per_um", c.reverse_radial_n_per_um),
                ("lateral_n_per_um", c.lateral_n_per_um),
            ] {
                if !(v.is_finite() && v > 0.0 && v <= 1e5) {
                    return Err(MachineError::new(
                        file,
                        key(k),
                        format!("{} must lie in (0, 1e5] N/µm", crate::text::num(v)),
                    ));
                }
            }
            // One value per id: a second entry would silently change every machine using it.
            if let Some(first) = self.files.get(&c.id) {
                return Err(MachineError::new(
                    file,
                    key("id"),
                    format!("already defined in {first}; give this entry its own id"),
                ));
            }
            self.files.insert(c.id.clone(), file.to_string());
            self.entries.insert(
                c.id.clone(),
                CarriageData {
                    radial_n_per_m: c.radial_n_per_um * 1e6,
                    reverse_radial_n_per_m: c.reverse_radial_n_per_um * 1e6,
                    lateral_n_per_m: c.lateral_n_per_um * 1e6,
                    estimated: c.estimated,
                    source: c.source,
                    id: c.id,
                },
            );
        }
        Ok(())
    }

    /// Looks up an entry.
    pub fn get(&self, id: &str) -> Option<&CarriageData> {
        self.entries.get(id)
    }

    /// All ids, sorted.
    pub fn ids(&self) -> impl Iterator<Item = &str> {
        self.entries.keys().map(String::as_str)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_catalogue_has_the_published_hiwin_values() {
        let c = Catalogue::bundled().unwrap();
        let published = [
            (15, [196.0, 365.0, 483.0]),
            (20, [232.0, 460.0, 678.0]),
            (25, [292.0, 539.0, 705.0]),
            (30, [354.0, 618.0, 823.0]),
        ];
        for (size, values) in published {
            for (preload, v) in ["Z0", "ZA", "ZB"].iter().zip(values) {
                let e = c.get(&format!("HIWIN HGH{size}CA {preload}")).unwrap();
                assert_eq!(e.radial_n_per_m, v * 1e6);
                assert!(e.estimated.iter().any(|s| s == "lateral_n_per_um"));
            }
        }
    }
}

//! The 25 MERL materials the project uses, and how a material's table is obtained.
//!
//! Resolution order for a material name:
//! 1. a real MERL binary `<merl_dir>/<name>.binary` when a MERL directory is configured and has
//!    it (labelled "MERL");
//! 2. otherwise the NBRDF network shipped in this crate, tabulated into a MERL table
//!    (labelled "MERL-derived (NBRDF)").
//!
//! The selection spans diffuse, plastic, paint, fabric, wood, stone, rubber and metal, and
//! includes the six materials the paper's figures show.

use crate::error::{Error, Result};
use crate::merl::MerlBrdf;
use crate::nbrdf::{Nbrdf, TabulationReport};
use std::path::Path;

/// Broad appearance class of a material.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MaterialClass {
    /// Matte, nearly Lambertian.
    Diffuse,
    /// Plastics, acrylics, phenolics.
    Plastic,
    /// Paints, including metallic paints.
    Paint,
    /// Fabrics and felts.
    Fabric,
    /// Woods.
    Wood,
    /// Stones and minerals.
    Stone,
    /// Rubbers and latex.
    Rubber,
    /// Metals.
    Metal,
}

/// One catalogue entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CatalogueEntry {
    /// The MERL name, for example "blue-acrylic".
    pub name: &'static str,
    /// Its appearance class.
    pub class: MaterialClass,
    json: &'static str,
}

macro_rules! entry {
    ($name:literal, $class:ident) => {
        CatalogueEntry {
            name: $name,
            class: MaterialClass::$class,
            json: include_str!(concat!("../assets/nbrdf/", $name, ".json")),
        }
    };
}

/// The project's 25 materials (MERL names).
pub const CATALOGUE: [CatalogueEntry; 25] = [
    entry!("grease-covered-steel", Metal),
    entry!("blue-acrylic", Plastic),
    entry!("ipswich-pine-221", Wood),
    entry!("white-marble", Stone),
    entry!("maroon-plastic", Plastic),
    entry!("green-latex", Rubber),
    entry!("white-diffuse-bball", Diffuse),
    entry!("yellow-matte-plastic", Diffuse),
    entry!("pink-felt", Fabric),
    entry!("blue-fabric", Fabric),
    entry!("red-fabric", Fabric),
    entry!("gold-metallic-paint", Paint),
    entry!("dark-red-paint", Paint),
    entry!("white-paint", Paint),
    entry!("pearl-paint", Paint),
    entry!("specular-red-phenolic", Plastic),
    entry!("black-phenolic", Plastic),
    entry!("cherry-235", Wood),
    entry!("special-walnut-224", Wood),
    entry!("pink-jasper", Stone),
    entry!("hematite", Stone),
    entry!("aluminium", Metal),
    entry!("chrome-steel", Metal),
    entry!("brass", Metal),
    entry!("alum-bronze", Metal),
];

/// Where a material's table came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MaterialSource {
    /// A real MERL binary at this path.
    Measured(std::path::PathBuf),
    /// The shipped NBRDF network, tabulated.
    NbrdfDerived(TabulationReport),
}

impl MaterialSource {
    /// The label every result computed from this material carries.
    pub fn label(&self) -> &'static str {
        match self {
            Self::Measured(_) => "MERL",
            Self::NbrdfDerived(_) => "MERL-derived (NBRDF)",
        }
    }
}

/// A resolved material: its table and provenance.
#[derive(Clone, Debug)]
pub struct Material {
    /// The MERL name.
    pub name: String,
    /// The appearance class.
    pub class: MaterialClass,
    /// Where the table came from.
    pub source: MaterialSource,
    /// The MERL table.
    pub table: MerlBrdf,
}

/// The catalogue entry of a name.
pub fn entry(name: &str) -> Result<&'static CatalogueEntry> {
    CATALOGUE.iter().find(|e| e.name == name).ok_or_else(|| Error::UnknownMaterial {
        name: name.into(),
        known: CATALOGUE.iter().map(|e| e.name).collect::<Vec<_>>().join(", "),
    })
}

impl CatalogueEntry {
    /// The shipped NBRDF network of this material.
    pub fn nbrdf(&self) -> Result<Nbrdf> {
        Nbrdf::from_json(self.json, &format!("shipped NBRDF network {}", self.name))
    }

    /// The shipped network's JSON text (unchanged from the published file).
    pub fn nbrdf_json(&self) -> &'static str {
        self.json
    }
}

/// Resolves a catalogue material: the real MERL binary from `merl_dir` when present, else the
/// shipped NBRDF network tabulated.
pub fn load_material(name: &str, merl_dir: Option<&Path>) -> Result<Material> {
    let e = entry(name)?;
    if let Some(dir) = merl_dir {
        let path = dir.join(format!("{name}.binary"));
        if path.is_file() {
            let table = MerlBrdf::read(&path)?;
            return Ok(Material {
                name: name.into(),
                class: e.class,
                source: MaterialSource::Measured(path),
                table,
            });
        }
    }
    let (table, report) = e.nbrdf()?.tabulate()?;
    Ok(Material {
        name: name.into(),
        class: e.class,
        source: MaterialSource::NbrdfDerived(report),
        table,
    })
}

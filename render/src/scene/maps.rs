//! A skin material's chromophore-map keys (`maps`, `melanin_map`, `eumelanin_map`,
//! `hemoglobin_map`, the edits and `edit_mask`, `profile_blend`, `map_profile_error`,
//! `thin_epidermis`, `thin_epidermis_mm`): each file
//! read through the guarded reader and decoded by `material::maps`, every error naming its key.

use super::fitted_maps;
use super::load::Loader;
use crate::error::RenderError;
use crate::fidelity::grid::DEFAULT_GRID_ERROR;
use crate::material::hetero::ProfileBlend;
use crate::material::maps::{
    ChromophoreMaps, Edit, MapInputs, Parameter, Source, THIN_EPIDERMIS_ATTRIBUTE,
    THIN_EPIDERMIS_CHANNEL, ThinInput, ValueImage, read_maps_exr, read_value_image,
};
use crate::material::{SkinBuildError, SkinKnobs, SkinMaterial};
use crate::texture::Texture;
use skin_optics::SkinParams;
use std::path::PathBuf;

/// The map keys of one skin material, as parsed.
#[derive(Debug, Clone, Copy)]
pub(super) struct MapKeys<'a> {
    pub maps: &'a Option<String>,
    /// `fit_maps`: the exposure under which the maps are fitted to the albedo texture.
    pub fit_maps: &'a Option<String>,
    /// The material's albedo texture and its file name, if it has one.
    pub albedo: Option<(&'a Texture, Option<&'a str>)>,
    /// `melanin_map`, `eumelanin_map`, `hemoglobin_map`.
    pub per_parameter: [&'a Option<String>; 3],
    /// (scale, offset) of melanin, then of hemoglobin.
    pub edits: [(&'a Option<f64>, &'a Option<f64>); 2],
    /// `melanin_ita_deg`: the ITA° the melanin offset brings the typical skin to.
    pub melanin_ita_deg: &'a Option<f64>,
    pub edit_mask: &'a Option<String>,
    pub profile_blend: &'a Option<String>,
    pub map_profile_error: &'a Option<f32>,
    pub map_incidence_error: &'a Option<f32>,
    /// `thin_epidermis` (whether flagged texels take it) and `thin_epidermis_mm`.
    pub thin_epidermis: (&'a Option<bool>, &'a Option<f64>),
}

impl Loader<'_> {
    /// `skin` with `maps`, the maps its keys gave (`skin` unchanged when there are none).
    pub(super) fn skin_with_maps(
        &self,
        key: &str,
        skin: SkinMaterial,
        maps: Option<ChromophoreMaps>,
        keys: &MapKeys<'_>,
        knobs: &SkinKnobs,
    ) -> Result<SkinMaterial, RenderError> {
        let edited = keys.edits.iter().any(|(s, o)| s.is_some() || o.is_some())
            || keys.melanin_ita_deg.is_some();
        let Some(maps) = maps else {
            let thin = keys.thin_epidermis.0.is_some() || keys.thin_epidermis.1.is_some();
            if edited
                || keys.profile_blend.is_some()
                || keys.map_profile_error.is_some()
                || keys.map_incidence_error.is_some()
                || thin
            {
                return Err(self.err(
                    key,
                    "the edits, melanin_ita_deg, profile_blend, map_profile_error, \
                     map_incidence_error, \
                     thin_epidermis and thin_epidermis_mm need a map (maps, fit_maps, melanin_map, eumelanin_map, \
                     hemoglobin_map or edit_mask)",
                ));
            }
            return Ok(skin);
        };
        let blend = match keys.profile_blend {
            Some(b) => b
                .parse::<ProfileBlend>()
                .map_err(|e| self.err(format!("{key}.profile_blend"), e.to_string()))?,
            None => ProfileBlend::default(),
        };
        let target = |name: &str, value: &Option<f32>, default: f32| match *value {
            Some(e) if e > 0.0 && e < 1.0 => Ok(e),
            Some(e) => Err(self.err(format!("{key}.{name}"), format!("{e} outside (0, 1)"))),
            None => Ok(default),
        };
        let targets = (
            target(
                "map_profile_error",
                keys.map_profile_error,
                DEFAULT_GRID_ERROR,
            )?,
            target(
                "map_incidence_error",
                keys.map_incidence_error,
                crate::fidelity::incidence::DEFAULT_INCIDENCE_ERROR,
            )?,
        );
        skin.with_maps(maps, blend, knobs, targets)
            .map_err(|e: SkinBuildError| self.err(key, e.to_string()))
    }

    /// The maps of a skin's keys over its scalar skin `params`: each given file read and
    /// decoded, the scalars filling the parameters without one, the edits applied; `None` when
    /// no map or mask is given.
    pub(super) fn chromophore_maps(
        &self,
        key: &str,
        params: &SkinParams,
        keys: &MapKeys<'_>,
    ) -> Result<Option<ChromophoreMaps>, RenderError> {
        let read = |name: &str, spec: &str| -> Result<(Vec<u8>, PathBuf), RenderError> {
            let map_key = format!("{key}.{name}");
            self.read(skin_io::input::CHROMOPHORE_MAP, spec)
                .map(|(b, p)| (b.into_owned(), p))
                .map_err(|e| RenderError::ChromophoreMap {
                    key: map_key,
                    path: PathBuf::from(spec),
                    message: e.to_string(),
                })
        };
        let named = |name: &str, spec: &str, e: RenderError| RenderError::ChromophoreMap {
            key: format!("{key}.{name}"),
            path: PathBuf::from(spec),
            message: e.to_string(),
        };
        let mut from_exr: [Option<ValueImage>; 3] = [None, None, None];
        // The file the maps came from, and the key that named it.
        let mut exr_source: Option<(&str, String)> =
            keys.maps.as_deref().map(|s| ("maps", s.to_string()));
        let (thin_on, thin_key_mm) = (
            keys.thin_epidermis.0.unwrap_or(true),
            *keys.thin_epidermis.1,
        );
        let thin_mm_key = format!("{key}.thin_epidermis_mm");
        // The thickness of a thin epidermis: (0, 10] mm as SkinParams takes it.
        let check_mm = |mm: f64| -> Result<f32, String> {
            params
                .with_epidermis_thickness_mm(mm)
                .map(|_| mm as f32)
                .map_err(|e| e.to_string())
        };
        if let Some(mm) = thin_key_mm {
            check_mm(mm).map_err(|e| self.err(&thin_mm_key, e))?;
        }
        let mut thin: Option<ThinInput> = None;
        if let Some(spec) = keys.maps {
            let (bytes, path) = read("maps", spec)?;
            let exr = read_maps_exr(&bytes, &path).map_err(|e| named("maps", spec, e))?;
            from_exr = exr.parameters;
            if let (true, Some(image)) = (thin_on, exr.thin_epidermis) {
                let map_key = format!("{key}.maps");
                let file_err = |message: String| RenderError::ChromophoreMap {
                    key: map_key.clone(),
                    path: PathBuf::from(spec),
                    message,
                };
                let thickness_mm = match (thin_key_mm, exr.thin_epidermis_mm) {
                    (Some(mm), _) => mm as f32,
                    (None, Some(mm)) => check_mm(mm).map_err(|e| {
                        file_err(format!("attribute {THIN_EPIDERMIS_ATTRIBUTE} = {mm}: {e}"))
                    })?,
                    (None, None) => {
                        return Err(file_err(format!(
                            "channel {THIN_EPIDERMIS_CHANNEL} without the attribute \
                             {THIN_EPIDERMIS_ATTRIBUTE} (the thin epidermis' thickness, which \
                             skin maps records): give {thin_mm_key} (skin maps' --thin-epidermis, \
                             0.05 mm by default) or {key}.thin_epidermis = false"
                        )));
                    }
                };
                thin = Some(ThinInput {
                    key: map_key,
                    path: PathBuf::from(spec),
                    image,
                    thickness_mm,
                });
            }
        }
        if let Some(exposure) = keys.fit_maps {
            let fit_key = format!("{key}.fit_maps");
            if keys.maps.is_some() {
                return Err(self.err(fit_key, "give maps or fit_maps, not both"));
            }
            let Some((texture, name)) = keys.albedo else {
                return Err(self.err(fit_key, "needs an albedo_texture to fit the maps to"));
            };
            // The fit is the same whether the flag is then read or not: `thin_epidermis = false`
            // only renders every texel under the material's epidermis.
            let thin_mm = thin_key_mm.unwrap_or(skin_fit::maps::THIN_EPIDERMIS_MM);
            let fitted = fitted_maps::fit(texture, exposure, Some(thin_mm))
                .map_err(|e| self.err(&fit_key, e))?;
            from_exr = fitted.parameters.map(Some);
            let source = name.unwrap_or("albedo_texture").to_string();
            thin = fitted
                .thin
                .filter(|_| thin_on)
                .map(|(image, mm)| ThinInput {
                    key: fit_key.clone(),
                    path: PathBuf::from(&source),
                    image,
                    thickness_mm: mm as f32,
                });
            exr_source = Some(("fit_maps", source));
        }
        let scalars = [
            params.melanin(),
            params.eumelanin_blend(),
            params.hemoglobin(),
        ];
        let mut sources: [Source; 3] = scalars.map(Source::Scalar);
        for (k, param) in Parameter::ALL.iter().enumerate() {
            let name = format!("{}_map", param.channel());
            if let Some(spec) = keys.per_parameter[k] {
                let (bytes, path) = read(&name, spec)?;
                let image = read_value_image(&bytes, &path, param.channel())
                    .map_err(|e| named(&name, spec, e))?;
                sources[k] = Source::Map {
                    key: format!("{key}.{name}"),
                    path: PathBuf::from(spec),
                    image,
                };
            } else if let (Some(image), Some((source_key, spec))) =
                (from_exr[k].take(), &exr_source)
            {
                sources[k] = Source::Map {
                    key: format!("{key}.{source_key}"),
                    path: PathBuf::from(spec),
                    image,
                };
            }
        }
        let mask = match keys.edit_mask {
            Some(spec) => {
                let (bytes, path) = read("edit_mask", spec)?;
                let image = read_value_image(&bytes, &path, "mask")
                    .map_err(|e| named("edit_mask", spec, e))?;
                Some((format!("{key}.edit_mask"), PathBuf::from(spec), image))
            }
            None => None,
        };
        let edit = |(scale, offset): (&Option<f64>, &Option<f64>)| Edit {
            scale: scale.unwrap_or(1.0),
            offset: offset.unwrap_or(0.0),
        };
        let mut inputs = MapInputs {
            material_key: key.to_string(),
            sources,
            edits: [
                (Parameter::Melanin, edit(keys.edits[0])),
                (Parameter::Hemoglobin, edit(keys.edits[1])),
            ],
            mask,
            thin,
        };
        if let Some(target) = *keys.melanin_ita_deg {
            let ita_key = format!("{key}.melanin_ita_deg");
            if keys.edits[0].1.is_some() {
                return Err(self.err(ita_key, "give melanin_offset or melanin_ita_deg, not both"));
            }
            if inputs.mask.is_some() {
                return Err(self.err(
                    ita_key,
                    "an edit_mask shifts texels by different amounts, so no one offset sets the \
                     typical skin's ITA°: give melanin_offset with the mask",
                ));
            }
            let unshifted = ChromophoreMaps::assemble(inputs.clone())?;
            if let Some(maps) = unshifted {
                let offset =
                    offset_for_ita(params, &maps, target).map_err(|e| self.err(&ita_key, e))?;
                inputs.edits[0].1.offset = offset;
            }
        }
        ChromophoreMaps::assemble(inputs)
    }
}

/// The melanin offset o that gives the typical skin of `maps` (on `params`' other constants)
/// the ITA° `target_deg` ([`skin_optics::lab::Lab::ita_deg`], the exact model's colour under
/// D65 every 10 nm): without a mask every texel moves by o, and so does the median C_m, so o is
/// C_m* − C_m,typical, where C_m* solves ITA°(C_m*) = target by bisection (ITA° falls as C_m
/// rises). o is kept within what leaves every texel in [0, 1]; a target beyond that range is an
/// error naming the reachable ITA°.
fn offset_for_ita(
    params: &SkinParams,
    maps: &ChromophoreMaps,
    target_deg: f64,
) -> Result<f64, String> {
    if !(-90.0..=90.0).contains(&target_deg) {
        return Err(format!("{target_deg} outside [-90, 90] degrees"));
    }
    let [c_m, beta_m, c_h] = maps.typical().map(f64::from);
    let [lo, hi] = maps.range()[0].map(f64::from);
    let model = skin_fit::ColourModel::new(10.0, multipole::Method::Exact, *params)
        .map_err(|e| e.to_string())?;
    let ita = |melanin: f64| -> Result<f64, String> {
        let skin = model
            .skin(melanin, beta_m, c_h.max(f64::MIN_POSITIVE))
            .map_err(|e| e.to_string())?;
        Ok(model.lab(&skin).map_err(|e| e.to_string())?.ita_deg())
    };
    // The typical C_m can move from c_m − lo (the lightest texel at 0) to c_m + 1 − hi.
    let (mut a, mut b) = (c_m - lo, c_m + 1.0 - hi);
    let (ita_a, ita_b) = (ita(a)?, ita(b)?);
    if !(ita_b..=ita_a).contains(&target_deg) {
        return Err(format!(
            "{target_deg} outside the ITA° the maps' typical skin reaches with every texel in \
             [0, 1]: [{ita_b:.1}, {ita_a:.1}]"
        ));
    }
    for _ in 0..40 {
        let mid = 0.5 * (a + b);
        if ita(mid)? > target_deg {
            a = mid;
        } else {
            b = mid;
        }
    }
    Ok(0.5 * (a + b) - c_m)
}

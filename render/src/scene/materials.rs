//! The materials of a scene file: skin (preset and overrides, surface lobe, texture) and diffuse
//! backdrops (constant, sRGB, sampled or textured albedo). Each key is checked here; the skin's
//! physics is built by [`SkinMaterial::build`].

use super::load::Loader;
use super::maps::MapKeys;
use crate::error::RenderError;
use crate::fidelity::{FidelityKnobs, LodBand, LodSetting};
use crate::material::{
    DiffuseMaterial, Material, SkinBuildError, SkinKnobs, SkinMaterial, SurfaceKind, TextureRef,
};
use crate::scene_file::{FidelityDesc, LodDesc, MaterialDesc};
use crate::spectrum::{SpectrumTable, linear_srgb_to_spectrum};
use crate::texture::{Texture, luminance};
use skin_optics::echo::Num;
use skin_optics::measured::named_skin;
use skin_optics::{Preset, SkinParams};
use std::collections::{BTreeMap, HashMap};

/// Materials in name order (as the file's table is read), their names (same order) and the textures
/// they use.
type Materials = (Vec<Material>, Vec<String>, Vec<Texture>);

impl Loader<'_> {
    /// Every material of the file, each texture read once; `footprints_mm[i]` is the smallest
    /// pixel footprint on material i's meshes, mm (the shape photons' choice).
    pub(super) fn materials(
        &self,
        descs: &BTreeMap<String, MaterialDesc>,
        knobs: &SkinKnobs,
        footprints_mm: &[Option<f32>],
    ) -> Result<Materials, RenderError> {
        let mut textures = Vec::new();
        let mut texture_ids: HashMap<String, usize> = HashMap::new();
        let mut material_names = Vec::new();
        let mut materials = Vec::new();
        for (index, (name, m)) in descs.iter().enumerate() {
            let key = format!("materials.{name}");
            let mut texture = |spec: &Option<String>| -> Result<Option<TextureRef>, RenderError> {
                let Some(spec) = spec else { return Ok(None) };
                let index = match texture_ids.get(spec) {
                    Some(&i) => i,
                    None => {
                        let (bytes, path) = self.read(skin_io::input::TEXTURE, spec)?;
                        textures.push(Texture::from_srgb_bytes(&bytes, &path)?);
                        texture_ids.insert(spec.clone(), textures.len() - 1);
                        textures.len() - 1
                    }
                };
                let mean_luminance = luminance(textures[index].mean()).max(1e-6);
                Ok(Some(TextureRef {
                    index,
                    mean_luminance,
                }))
            };
            let material = match m {
                MaterialDesc::Skin {
                    preset,
                    melanin,
                    eumelanin,
                    hemoglobin,
                    oil,
                    roughness,
                    albedo_texture,
                    phase_g,
                    surface,
                    maps,
                    fit_maps,
                    melanin_map,
                    eumelanin_map,
                    hemoglobin_map,
                    melanin_scale,
                    melanin_offset,
                    melanin_ita_deg,
                    hemoglobin_scale,
                    hemoglobin_offset,
                    edit_mask,
                    profile_blend,
                    map_profile_error,
                    map_incidence_error,
                    thin_epidermis,
                    thin_epidermis_mm,
                } => {
                    let params =
                        self.skin_params(&key, preset, [*melanin, *eumelanin, *hemoglobin, *oil])?;
                    let m_rough = roughness.unwrap_or(brdf::DEFAULT_ROUGHNESS);
                    let rough_err =
                        |e: brdf::BrdfError| self.err(format!("{key}.roughness"), e.to_string());
                    brdf::check_roughness(m_rough).map_err(rough_err)?;
                    let tex = texture(albedo_texture)?;
                    let mut knobs = self.skin_knobs(knobs, &key, *phase_g, surface.as_deref())?;
                    knobs.fidelity.smallest_footprint_mm =
                        footprints_mm.get(index).copied().flatten();
                    let map_keys = MapKeys {
                        maps,
                        fit_maps,
                        albedo: tex.map(|t| (&textures[t.index], albedo_texture.as_deref())),
                        per_parameter: [melanin_map, eumelanin_map, hemoglobin_map],
                        edits: [
                            (melanin_scale, melanin_offset),
                            (hemoglobin_scale, hemoglobin_offset),
                        ],
                        melanin_ita_deg,
                        edit_mask,
                        profile_blend,
                        map_profile_error,
                        map_incidence_error,
                        thin_epidermis: (thin_epidermis, thin_epidermis_mm),
                    };
                    let maps = self.chromophore_maps(&key, &params, &map_keys)?;
                    // With maps, the scalar skin is the maps' typical skin
                    // (`ChromophoreMaps::typical`), not the material's default.
                    let params = match &maps {
                        Some(m) => {
                            let [c_m, beta_m, c_h] = m.typical().map(f64::from);
                            params
                                .with_melanin(c_m)
                                .and_then(|p| p.with_eumelanin_blend(beta_m))
                                .and_then(|p| p.with_hemoglobin(c_h.max(f64::MIN_POSITIVE)))
                                .map_err(|e| self.err(&key, e.to_string()))?
                        }
                        None => params,
                    };
                    let skin =
                        SkinMaterial::build(params, m_rough, tex, &knobs).map_err(|e| match e {
                            SkinBuildError::Surface(e) => rough_err(e),
                            other => self.err(&key, other.to_string()),
                        })?;
                    let skin = self.skin_with_maps(&key, skin, maps, &map_keys, &knobs)?;
                    Material::Skin(skin)
                }
                MaterialDesc::Diffuse {
                    albedo,
                    albedo_srgb,
                    albedo_spectrum,
                    albedo_texture,
                } => {
                    let set = [
                        albedo.is_some(),
                        albedo_srgb.is_some(),
                        albedo_spectrum.is_some(),
                    ];
                    let table = match (albedo, albedo_srgb, albedo_spectrum) {
                        _ if set.iter().filter(|&&s| s).count() > 1 => {
                            return Err(self.err(
                                &key,
                                "give only one of albedo, albedo_srgb, albedo_spectrum",
                            ));
                        }
                        (Some(a), _, _) => {
                            SpectrumTable::constant(self.unit(&format!("{key}.albedo"), *a)?)
                        }
                        (_, Some(rgb), _) => {
                            let mut lin = [0.0; 3];
                            for (i, &c) in rgb.iter().enumerate() {
                                let c = self.unit(&format!("{key}.albedo_srgb"), c)?;
                                lin[i] = skin_optics::color::srgb_decode(f64::from(c)) as f32;
                            }
                            linear_srgb_to_spectrum(lin)
                        }
                        (_, _, Some(samples)) => {
                            self.sampled_albedo(&format!("{key}.albedo_spectrum"), samples)?
                        }
                        _ if albedo_texture.is_some() => SpectrumTable::constant(1.0),
                        _ => {
                            return Err(self.err(
                                &key,
                                "expected one of albedo, albedo_srgb, albedo_spectrum",
                            ));
                        }
                    };
                    Material::Diffuse(DiffuseMaterial {
                        albedo: table,
                        albedo_texture: texture(albedo_texture)?,
                    })
                }
            };
            material_names.push(name.clone());
            materials.push(material);
        }
        Ok((materials, material_names, textures))
    }

    /// The scene's `[fidelity]` keys, each checked (the defaults without the table).
    pub(super) fn fidelity(
        &self,
        desc: Option<&FidelityDesc>,
    ) -> Result<FidelityKnobs, RenderError> {
        let Some(d) = desc else {
            return Ok(FidelityKnobs::default());
        };
        let fidelity = d.fidelity.as_deref().map(str::parse).transpose().map_err(
            |e: crate::fidelity::UnknownFidelity| self.err("fidelity.fidelity", e.to_string()),
        )?;
        let lod = match &d.lod {
            None => LodSetting::ByFidelity,
            Some(LodDesc::Word(w)) if w.eq_ignore_ascii_case("off") => LodSetting::Off,
            Some(LodDesc::Word(w)) => {
                return Err(self.err(
                    "fidelity.lod",
                    format!("expected \"off\" or [LO, HI], got \"{w}\""),
                ));
            }
            Some(LodDesc::Band([lo, hi])) => LodSetting::Band(LodBand {
                full_below: *lo,
                diffuse_above: *hi,
            }),
        };
        let knobs = FidelityKnobs {
            fidelity,
            energy_tolerance: d.energy_tolerance,
            radial_error: d.radial_error,
            wavelength_step_nm: d.wavelength_step_nm,
            lod,
            thin_walk_r99: d.thin_walk,
            shape_photons: d.shape_photons,
            image_height: None,
            smallest_footprint_mm: None,
            cache: true,
        };
        knobs
            .resolve()
            .map_err(|e| self.err(e.name, format!("{} outside {}", e.value, e.range)))?;
        Ok(knobs)
    }

    /// The scene's skin knobs with this material's `phase_g` and `surface` keys applied.
    fn skin_knobs(
        &self,
        base: &SkinKnobs,
        key: &str,
        phase_g: Option<f64>,
        surface: Option<&str>,
    ) -> Result<SkinKnobs, RenderError> {
        let mut knobs = *base;
        if let Some(g) = phase_g {
            if !(0.0..=0.99).contains(&g) {
                return Err(self.err(
                    format!("{key}.phase_g"),
                    format!("expected a value in [0, 0.99], got {}", Num(g)),
                ));
            }
            knobs.phase_g = Some(g);
        }
        if let Some(s) = surface {
            knobs.surface = s
                .parse::<SurfaceKind>()
                .map_err(|e| self.err(format!("{key}.surface"), e))?;
        }
        Ok(knobs)
    }

    fn unit(&self, key: &str, v: f32) -> Result<f32, RenderError> {
        if v.is_finite() && (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err(self.err(key, format!("expected a value in [0, 1], got {v}")))
        }
    }

    fn sampled_albedo(&self, key: &str, s: &[[f64; 2]]) -> Result<SpectrumTable, RenderError> {
        if s.is_empty() || s.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return Err(self.err(key, "expected [nm, value] pairs with increasing nm"));
        }
        for p in s {
            self.unit(key, p[1] as f32)?;
        }
        Ok(SpectrumTable::from_fn(|nm| {
            let i = s.partition_point(|p| p[0] <= nm);
            if i == 0 {
                s[0][1]
            } else if i == s.len() {
                s[s.len() - 1][1]
            } else {
                let (a, b) = (s[i - 1], s[i]);
                a[1] + (nm - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
            }
        }))
    }

    /// The named skin (a seed or a measured preset, [`skin_optics::measured::named_skin`]) with
    /// explicit fractions replacing its values; its other parameters (a measured preset's
    /// oxygenation, epidermis thickness, scattering scales, extended physiology) are kept. An
    /// invalid value is reported by its key.
    fn skin_params(
        &self,
        key: &str,
        preset: &Option<String>,
        overrides: [Option<f64>; 4],
    ) -> Result<SkinParams, RenderError> {
        let base = match preset {
            Some(p) => {
                named_skin(p).map_err(|e| self.err(format!("{key}.preset"), e.to_string()))?
            }
            None => SkinParams::preset(Preset::Light),
        };
        let [melanin, eumelanin, hemoglobin, oil] = overrides;
        let named = |name: &str, r: Result<SkinParams, skin_optics::OpticsError>| {
            r.map_err(|e| self.err(format!("{key}.{name}"), e.to_string()))
        };
        let s = named(
            "melanin",
            base.with_melanin(melanin.unwrap_or(base.melanin())),
        )?;
        let s = named(
            "eumelanin",
            s.with_eumelanin_blend(eumelanin.unwrap_or(base.eumelanin_blend())),
        )?;
        let s = named(
            "hemoglobin",
            s.with_hemoglobin(hemoglobin.unwrap_or(base.hemoglobin())),
        )?;
        named("oil", s.with_oiliness(oil.unwrap_or(base.oiliness())))
    }
}

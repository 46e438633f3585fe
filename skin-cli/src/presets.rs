//! `skin presets`: the named skins with their colour (CIELAB under D65, sRGB) and ITA°.

use clap::Args;
use skin_fit::named_skins;
use skin_optics::SkinParams;
use skin_optics::lab::Lab;

/// Arguments of `skin presets`.
#[derive(Args, Debug, Clone)]
pub struct PresetsArgs {
    /// Print one JSON array instead of a table.
    #[arg(long)]
    pub json: bool,
}

fn row(name: &str, what: &str, lab: Lab) -> String {
    format!(
        "{name:<18} {}  L*a*b* ({:5.1}, {:5.1}, {:5.1})  ITA° {:6.1} ({:<12}) {what}",
        lab.to_srgb().to_hex(),
        lab.l,
        lab.a,
        lab.b,
        lab.ita_deg(),
        lab.ita_category().name()
    )
}

fn json_row(name: &str, what: &str, skin: &SkinParams, lab: Lab) -> serde_json::Value {
    serde_json::json!({
        "name": name, "source": what, "srgb": lab.to_srgb().to_hex(),
        "lab": { "l": lab.l, "a": lab.a, "b": lab.b },
        "ita_deg": lab.ita_deg(), "ita_category": lab.ita_category().name(),
        "melanin": skin.melanin(), "eumelanin_blend": skin.eumelanin_blend(),
        "hemoglobin": skin.hemoglobin(), "oiliness": skin.oiliness(),
    })
}

/// Run `skin presets`.
pub fn run(args: &PresetsArgs) -> anyhow::Result<()> {
    let rows: Vec<_> = named_skins()?
        .into_iter()
        .map(|r| (r.name, r.source, r.skin, r.lab))
        .collect();
    if args.json {
        let v: Vec<_> = rows
            .iter()
            .map(|(n, w, s, l)| json_row(n, w, s, *l))
            .collect();
        println!("{}", serde_json::Value::Array(v));
    } else {
        for (n, w, _, l) in &rows {
            println!("{}", row(n, w, *l));
        }
    }
    Ok(())
}

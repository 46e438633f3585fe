//! Write a 4096 × 4096 8-bit sRGB PNG of the built-in head's albedo texture (bilinear upscale)
//! for timing `skin maps` on a production-size texture.
//! Run: `cargo run --release -p skin-fit --example maps_upscale -- render/assets/Map-COL.jpg OUT.png`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (input, output) = (args.get(1).ok_or("input")?, args.get(2).ok_or("output")?);
    let img = image::open(input)?.to_rgb8();
    let big = image::imageops::resize(&img, 4096, 4096, image::imageops::FilterType::Triangle);
    big.save(output)?;
    Ok(())
}

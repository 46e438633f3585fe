//! Resize an image to SIDE pixels wide (height in proportion; bilinear) and save it as 8-bit PNG:
//! the 4096 × 4096 head texture that times `skin maps` at production size, and the small copies
//! of its outputs in docs/images/maps/.
//! Run: `cargo run --release -p skin-fit --features studies --example maps_resize -- IN OUT.png SIDE`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let input = args.get(1).ok_or("input image")?;
    let output = args.get(2).ok_or("output PNG")?;
    let side: u32 = args.get(3).ok_or("side, px")?.parse()?;
    let img = image::open(input)?.to_rgb8();
    let height = (u64::from(side) * u64::from(img.height()) / u64::from(img.width().max(1))) as u32;
    let out = image::imageops::resize(
        &img,
        side,
        height.max(1),
        image::imageops::FilterType::Triangle,
    );
    out.save(output)?;
    Ok(())
}

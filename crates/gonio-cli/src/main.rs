#[allow(dead_code)]
mod bench;
fn main() {}

//! The `yawcast` command-line tool.
fn main() {
    println!("yawcast");
}

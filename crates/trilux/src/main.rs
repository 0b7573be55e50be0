//! The `trilux` command.

fn main() {
    println!("trilux: under construction");
}

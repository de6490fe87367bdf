fn main() {
    println!("bondmech");
}

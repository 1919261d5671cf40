//! The `nanofold` binary.

mod cli;

use clap::Parser;

fn main() {
    let parsed = cli::Cli::parse();
    match cli::run(parsed) {
        Ok(true) => {}
        Ok(false) => std::process::exit(1),
        Err(e) => {
            let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": "));
            std::process::exit(2);
        }
    }
}

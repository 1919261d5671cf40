//! The `nanofold` binary.

mod cli;

use clap::Parser;

fn main() {
    // Rust ignores SIGPIPE, which turns a closed pipe into a panic in println!; a command
    // line tool should just stop, as `head` expects.
    #[cfg(unix)]
    // SAFETY: setting a signal's action to its default before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
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

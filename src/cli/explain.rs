//! `geomc explain CODE`: what a diagnostic means and how to fix it.

use super::{EXIT_OK, EXIT_USAGE, out};
use geomc::diag::Code;

#[derive(clap::Args)]
pub struct Args {
    /// A diagnostic code such as E201 (or `all` to list every code).
    code: String,
}

pub fn run(args: &Args) -> i32 {
    if args.code.eq_ignore_ascii_case("all") {
        let mut text = String::new();
        for code in Code::ALL {
            text.push_str(&format!(
                "{}  {:<8} {}\n",
                code.as_str(),
                code.severity().as_str(),
                code.title()
            ));
        }
        out(&text);
        return EXIT_OK;
    }
    match Code::parse(&args.code) {
        Some(code) => {
            out(&format!(
                "{} ({}): {}\n\n{}\n",
                code.as_str(),
                code.severity().as_str(),
                code.title(),
                code.explanation()
            ));
            EXIT_OK
        }
        None => {
            let names = Code::ALL.iter().map(|c| c.as_str());
            let hint = geomc::diag::did_you_mean(&args.code.to_uppercase(), names)
                .map_or(String::new(), |c| format!(" (did you mean {c}?)"));
            eprintln!(
                "geomc: no diagnostic code '{}'{hint}; `geomc explain all` lists them",
                args.code
            );
            EXIT_USAGE
        }
    }
}

//! POSIX shell quoting for the generated batch scripts: a word that needs no quotes stays as it
//! is (the scripts stay readable); any other is single-quoted, so nothing in it expands.

/// `word` as one shell word.
pub fn sh(word: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c);
    if !word.is_empty() && word.chars().all(plain) {
        word.to_owned()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

/// `words` as shell words separated by spaces.
pub fn sh_words<S: AsRef<str>>(words: &[S]) -> String {
    words.iter().map(|w| sh(w.as_ref())).collect::<Vec<_>>().join(" ")
}

/// Shell words (already quoted) on one logical line, continued with `\` past 96 columns.
pub fn wrap(words: &[String]) -> String {
    let mut line = String::new();
    let mut width = 0;
    for (n, w) in words.iter().enumerate() {
        if n > 0 && width + w.len() > 96 {
            line.push_str(" \\\n    ");
            width = 4;
        } else if n > 0 {
            line.push(' ');
            width += 1;
        }
        line.push_str(w);
        width += w.len();
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_words_stay_and_others_are_quoted() {
        assert_eq!(sh("frames/frame0001.exr"), "frames/frame0001.exr");
        assert_eq!(sh("my shot/dir"), "'my shot/dir'");
        assert_eq!(sh("it's"), r"'it'\''s'");
        assert_eq!(sh("$HOME"), "'$HOME'");
        assert_eq!(sh(""), "''");
        assert_eq!(sh_words(&["a b", "c"]), "'a b' c");
    }

    /// What bash makes of the quoted words is the words themselves (an independent reader).
    #[test]
    fn bash_reads_back_every_word() {
        let words = ["plain", "with space", "quote'in", "$(rm -rf x)", "tab\there", "*", "new\nline", ""];
        let out = std::process::Command::new("bash")
            .arg("-c")
            .arg(format!("printf '%s\\0' {}", sh_words(&words)))
            .output()
            .expect("run bash");
        let got: Vec<String> =
            out.stdout.split(|&b| b == 0).map(|s| String::from_utf8_lossy(s).into_owned()).collect();
        assert_eq!(&got[..words.len()], &words);
    }
}

//! Short excerpts of long expression sources, for error messages.

/// Expressions up to this many characters are quoted whole in error messages.
pub const EXCERPT_MAX_CHARS: usize = 100;
/// Characters shown on each side of the error position in a longer expression.
pub const EXCERPT_CONTEXT: usize = 40;

/// `src` as an error message quotes it: whole when it has at most [`EXCERPT_MAX_CHARS`]
/// characters; otherwise the [`EXCERPT_CONTEXT`] characters on each side of byte offset `pos`
/// (clamped to the source, rounded to character boundaries), with `…` where text was cut and
/// the position stated, e.g. `"…+ x*sin(t) + y…" (around column 51 201 of 102 400)`.
///
/// ```
/// use bondmech::expr::excerpt;
/// assert_eq!(excerpt("1/t", 2), "\"1/t\"");
/// let long = format!("{}+ ?", "t + ".repeat(1000));
/// let e = excerpt(&long, 4001);
/// assert!(e.len() < 150 && e.contains('?') && e.contains("column 4002 of 4003"), "{e}");
/// ```
pub fn excerpt(src: &str, pos: usize) -> String {
    let n = src.chars().count();
    if n <= EXCERPT_MAX_CHARS {
        return format!("\"{src}\"");
    }
    let pos = pos.min(src.len());
    // character index of the byte offset `pos` (the first character starting at or after it)
    let col = src.char_indices().take_while(|(b, _)| *b < pos).count();
    let start = col.saturating_sub(EXCERPT_CONTEXT);
    let end = (col + EXCERPT_CONTEXT).min(n);
    let text: String = src.chars().skip(start).take(end - start).collect();
    format!(
        "\"{}{}{}\" (around column {} of {})",
        if start > 0 { "…" } else { "" },
        text,
        if end < n { "…" } else { "" },
        col + 1,
        n
    )
}

use super::*;

#[test]
fn declarations_comments_quotes_and_entities() {
    let text = b"\xef\xbb\xbf<?xml version=\"1.0\"?>\n<!DOCTYPE x>\n<!-- <fake> -->\n<A  b = 'one &amp; two' c=\"&lt;&#65;&#x42;&gt;\"\n>\n  <B/><!-- c --><C d=\"1\">text<![CDATA[ <no/> ]]></C>\n</A >\n<!-- end -->\n";
    let root = parse_document(text).unwrap();
    assert_eq!(root.name, "A");
    assert_eq!(root.attribute("b"), Some("one & two"));
    assert_eq!(root.attribute("c"), Some("<AB>"));
    assert_eq!(root.children.len(), 2);
    let c = root.child("C").unwrap();
    assert_eq!(c.attribute("d"), Some("1"));
    assert!(text[c.content.clone()].starts_with(b"text"));
    assert_eq!(&*c.text_content(text), b"text <no/> ");
    let d = parse_document(b"<D> 1 2 <K a='1'><V>9</V></K> 3 <!-- x --> 4</D>").unwrap();
    assert_eq!(
        &*d.text_content(b"<D> 1 2 <K a='1'><V>9</V></K> 3 <!-- x --> 4</D>"),
        b" 1 2  3  4"
    );
    assert_eq!(line_of(text, c.offset), 6);
}

#[test]
fn appended_data_runs_to_the_last_closing_tag() {
    let text = b"<V><AppendedData encoding=\"raw\">_\x00<</AppendedData>\xff</AppendedData></V>";
    let root = parse_document(text).unwrap();
    let a = root.child("AppendedData").unwrap();
    assert_eq!(&text[a.content.clone()], b"_\x00<</AppendedData>\xff");
}

#[test]
fn syntax_errors_are_reported_not_panicked() {
    for bad in [
        &b""[..],
        b"<A",
        b"<A b>",
        b"<A b='1></A>",
        b"<A></B>",
        b"<A><B></A>",
        b"<A>",
        b"<A b='&bogus;'/>",
        b"<A b='1' b='2'/>",
        b"<A/>trailing",
        b"<!-- never closed",
    ] {
        assert!(
            parse_document(bad).is_err(),
            "{}",
            String::from_utf8_lossy(bad)
        );
    }
    let deep = "<a>".repeat(MAX_DEPTH + 1);
    assert!(parse_document(deep.as_bytes())
        .unwrap_err()
        .message
        .contains("deeper"));
}

//! HTML rendering: a [`Table`] as an HTML table with its highlighting, and self-contained pages
//! (inline CSS, no script, no network) built from sections. Like the rest of the crate it
//! returns strings; the caller writes the files and decides where images live.
//!
//! Best values are bold on a green tint, second underlined, third italic; improvements of
//! delta tables bold; the noise ceiling row is grey. [`links`] and [`check_well_formed`] are
//! the checks the report's tests run on every page.

use super::rank::Mark;
use super::table::Table;
use std::fmt::Write as _;

/// The page style: readable type, tables with ranked cells, figures that fit the window.
const CSS: &str = "body{font-family:system-ui,-apple-system,'DejaVu Sans',sans-serif;\
margin:2em auto;max-width:1200px;padding:0 1em;color:#222;line-height:1.45}\
h1{font-size:1.7em}h2{margin-top:2em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:1em 0;font-variant-numeric:tabular-nums}\
caption{caption-side:top;text-align:left;font-weight:600;padding:.3em 0}\
th,td{border:1px solid #ddd;padding:.25em .6em;text-align:right}\
th:first-child,td:first-child{text-align:left}thead th{background:#f4f4f4}\
td.best{font-weight:700;background:#e3f4e1}td.second{text-decoration:underline}\
td.third{font-style:italic}td.improved{font-weight:700}tr.reference td{color:#666;background:#fafafa}\
p.note{color:#555;font-size:.9em;margin:.2em 0}figure{margin:1em 0}\
figure img{width:100%;height:auto;border:1px solid #ddd}figcaption{color:#555;font-size:.9em}\
.grid{display:flex;flex-wrap:wrap;gap:1em}.grid figure{flex:1 1 300px;max-width:420px}\
pre{background:#f6f6f6;padding:1em;overflow:auto;font-size:.85em}\
.meta{color:#555}ul.runs{columns:2}nav.toc{margin:.5em 0 1.5em;line-height:1.8}";

/// Escapes text for HTML content and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// The table as an HTML `<table>` (caption, group headers, marked cells), then its legend and
/// notes as paragraphs.
pub fn table_html(table: &Table) -> String {
    let columns = table.columns();
    let marks = table.marks();
    let mut out = String::from("<table>\n");
    if !table.caption.is_empty() {
        let _ = writeln!(out, "<caption>{}</caption>", escape(&table.caption));
    }
    out.push_str("<thead>\n");
    if table.groups.len() > 1 || table.groups.iter().any(|g| !g.title.is_empty()) {
        out.push_str("<tr><th></th>");
        for g in &table.groups {
            let _ = write!(out, "<th colspan=\"{}\">{}</th>", g.columns.len(), escape(&g.title));
        }
        out.push_str("</tr>\n");
    }
    let _ = write!(out, "<tr><th>{}</th>", escape(&table.stub_header));
    for c in &columns {
        let _ = write!(out, "<th>{}{}</th>", escape(&c.label), c.direction.arrow());
    }
    out.push_str("</tr>\n</thead>\n<tbody>\n");
    for (r, row) in table.rows.iter().enumerate() {
        let class = if row.reference { " class=\"reference\"" } else { "" };
        let _ = write!(out, "<tr{class}><td>{}</td>", escape(&row.label));
        for c in 0..columns.len() {
            let mark = marks.get(r).and_then(|m| m.get(c)).copied().unwrap_or(Mark::None);
            let class = match mark {
                Mark::None => "",
                Mark::First => " class=\"best\"",
                Mark::Second => " class=\"second\"",
                Mark::Third => " class=\"third\"",
                Mark::Improved => " class=\"improved\"",
            };
            let _ = write!(out, "<td{class}>{}</td>", escape(&table.cell_text(r, c)));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody>\n</table>\n");
    let legend = table.legend(["bold on green", "underlined", "italic", "bold (an improvement)"]);
    if !legend.is_empty() {
        let _ = writeln!(out, "<p class=\"note\">{}</p>", escape(&legend));
    }
    for note in &table.notes {
        let _ = writeln!(out, "<p class=\"note\">{}</p>", escape(note));
    }
    out
}

/// A page under construction: append sections, then [`Page::finish`].
#[derive(Clone, Debug)]
pub struct Page {
    title: String,
    body: String,
    /// (text, id) of every section heading: the contents line of [`Page::finish`].
    headings: Vec<(String, String)>,
}

impl Page {
    /// An empty page with a `<title>` and an `<h1>`.
    pub fn new(title: &str) -> Self {
        Page { title: title.to_string(), body: String::new(), headings: Vec::new() }
    }

    /// A section heading.
    pub fn heading(&mut self, text: &str, id: &str) -> &mut Self {
        let _ = writeln!(self.body, "<h2 id=\"{}\">{}</h2>", escape(id), escape(text));
        self.headings.push((text.to_string(), id.to_string()));
        self
    }

    /// A paragraph of plain text (class `meta` when `meta`).
    pub fn paragraph(&mut self, text: &str, meta: bool) -> &mut Self {
        let class = if meta { " class=\"meta\"" } else { "" };
        let _ = writeln!(self.body, "<p{class}>{}</p>", escape(text));
        self
    }

    /// A result table.
    pub fn table(&mut self, table: &Table) -> &mut Self {
        self.body.push_str(&table_html(table));
        self
    }

    /// Images side by side: (relative path, caption) each, linked to the full-size file.
    pub fn figures(&mut self, images: &[(String, String)]) -> &mut Self {
        let grid = images.len() > 1;
        if grid {
            self.body.push_str("<div class=\"grid\">\n");
        }
        for (src, caption) in images {
            let (src, caption) = (escape(src), escape(caption));
            let _ = writeln!(
                self.body,
                "<figure><a href=\"{src}\"><img src=\"{src}\" alt=\"{caption}\"></a>\
                 <figcaption>{caption}</figcaption></figure>"
            );
        }
        if grid {
            self.body.push_str("</div>\n");
        }
        self
    }

    /// A list of links: (relative path, text) each.
    pub fn links(&mut self, links: &[(String, String)]) -> &mut Self {
        self.body.push_str("<ul class=\"runs\">\n");
        for (href, text) in links {
            let _ =
                writeln!(self.body, "<li><a href=\"{}\">{}</a></li>", escape(href), escape(text));
        }
        self.body.push_str("</ul>\n");
        self
    }

    /// Preformatted text (a JSON file).
    pub fn preformatted(&mut self, text: &str) -> &mut Self {
        let _ = writeln!(self.body, "<pre>{}</pre>", escape(text));
        self
    }

    /// The complete document: the title, a contents line linking every section (pages with
    /// three or more), then the sections.
    pub fn finish(&self) -> String {
        let mut head = format!("<h1>{}</h1>\n", escape(&self.title));
        if self.headings.len() >= 3 {
            head.push_str("<nav class=\"toc\">");
            for (i, (text, id)) in self.headings.iter().enumerate() {
                let sep = if i == 0 { "" } else { " · " };
                let _ = write!(head, "{sep}<a href=\"#{}\">{}</a>", escape(id), escape(text));
            }
            head.push_str("</nav>\n");
        }
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <title>{}</title>\n<style>{CSS}</style>\n</head>\n<body>\n{head}{}</body>\n</html>\n",
            escape(&self.title),
            self.body
        )
    }
}

/// Every `src` and `href` value of a page that names a file, unescaped, in order (links
/// within the page, `#id`, are checked by [`check_well_formed`]).
pub fn links(html: &str) -> Vec<String> {
    all_links(html).into_iter().filter(|l| !l.starts_with('#')).collect()
}

/// Every `src` and `href` value, unescaped, in order.
fn all_links(html: &str) -> Vec<String> {
    let mut out = Vec::new();
    for attr in ["src=\"", "href=\""] {
        let mut rest = html;
        while let Some(i) = rest.find(attr) {
            let after = &rest[i + attr.len()..];
            let Some(end) = after.find('"') else { break };
            let v = &after[..end];
            out.push(
                v.replace("&quot;", "\"")
                    .replace("&#39;", "'")
                    .replace("&lt;", "<")
                    .replace("&gt;", ">")
                    .replace("&amp;", "&"),
            );
            rest = &after[end..];
        }
    }
    out
}

/// Checks that every element a page opens is closed in order (void elements excepted) and
/// that the document has one `html`, `head` and `body`: the structure [`Page`] writes.
pub fn check_well_formed(html: &str) -> Result<(), String> {
    const VOID: [&str; 6] = ["meta", "img", "br", "hr", "link", "input"];
    let mut stack: Vec<String> = Vec::new();
    let mut rest = html;
    while let Some(i) = rest.find('<') {
        rest = &rest[i + 1..];
        let end = rest.find('>').ok_or("a tag is never closed with '>'")?;
        let tag = &rest[..end];
        rest = &rest[end + 1..];
        if tag.starts_with('!') {
            continue;
        }
        let (closing, body) = match tag.strip_prefix('/') {
            Some(b) => (true, b),
            None => (false, tag),
        };
        let name: String = body
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect::<String>()
            .to_ascii_lowercase();
        if name.is_empty() {
            return Err(format!("malformed tag <{tag}>"));
        }
        if VOID.contains(&name.as_str()) {
            continue;
        }
        if closing {
            match stack.pop() {
                Some(open) if open == name => {}
                Some(open) => return Err(format!("</{name}> closes <{open}>")),
                None => return Err(format!("</{name}> closes nothing")),
            }
        } else {
            stack.push(name);
        }
    }
    if let Some(open) = stack.pop() {
        return Err(format!("<{open}> is never closed"));
    }
    for required in ["<html", "<head>", "<body>"] {
        if html.matches(required).count() != 1 {
            return Err(format!("expected exactly one {required}"));
        }
    }
    for link in all_links(html) {
        if let Some(id) = link.strip_prefix('#')
            && !html.contains(&format!("id=\"{}\"", escape(id)))
        {
            return Err(format!("links to #{id}, which no element of the page has"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::record::MetricKind;
    use super::super::table::{Cell, Column, ColumnGroup, Marking, Row};
    use super::*;

    fn table() -> Table {
        Table {
            caption: "PSNR <test> & co".into(),
            stub_header: "Model".into(),
            groups: vec![ColumnGroup {
                title: "MERL".into(),
                columns: vec![Column::metric(MetricKind::Psnr)],
            }],
            rows: vec![
                Row::new("A", vec![Cell::value(30.0)]),
                Row::new("B", vec![Cell::value(32.0)]),
                Row::new("C", vec![Cell::value(31.0)]),
                Row::reference("ceiling", vec![Cell::value(40.0)]),
            ],
            marking: Marking::RankColumns,
            notes: vec!["a note".into()],
        }
    }

    #[test]
    fn tables_mark_ranks_and_escape() {
        let h = table_html(&table());
        assert!(h.contains("PSNR &lt;test&gt; &amp; co"), "{h}");
        assert!(h.contains("<td class=\"best\">32.00</td>"), "{h}");
        assert!(h.contains("<td class=\"second\">31.00</td>"), "{h}");
        assert!(h.contains("<td class=\"third\">30.00</td>"), "{h}");
        // The ceiling is shown but not ranked.
        assert!(h.contains("<tr class=\"reference\"><td>ceiling</td><td>40.00</td>"), "{h}");
        assert!(h.contains("<p class=\"note\">a note</p>"));
    }

    #[test]
    fn pages_are_well_formed_and_list_their_links() {
        let mut p = Page::new("Report \"x\"");
        p.heading("Tables", "tables").table(&table());
        p.figures(&[("../figures/a b.png".into(), "A".into()), ("c.png".into(), "C".into())]);
        p.links(&[("runs/r&1.html".into(), "run 1".into())]).preformatted("{\"a\": 1}");
        let html = p.finish();
        check_well_formed(&html).unwrap();
        assert_eq!(
            links(&html),
            vec!["../figures/a b.png", "c.png", "../figures/a b.png", "c.png", "runs/r&1.html"]
        );
        assert!(!html.contains("<nav"), "no contents line for one section");
        let mut q = Page::new("Contents");
        for (t, id) in [("One", "one"), ("Two", "two"), ("Three", "three")] {
            q.heading(t, id);
        }
        let html = q.finish();
        check_well_formed(&html).unwrap();
        assert!(html.contains("<a href=\"#two\">Two</a>"), "{html}");
        assert!(links(&html).is_empty(), "in-page links are not files");
        let broken = html.replace("id=\"three\"", "id=\"four\"");
        assert!(check_well_formed(&broken).unwrap_err().contains("#three"));
        assert!(check_well_formed("<html><head></head><body><p></body></html>").is_err());
        assert!(check_well_formed("<html><head></head><body><p>").is_err());
        assert!(check_well_formed("<html><head></head><body></body>").is_err());
    }
}

//! The metadata text that `.part` films and golden images carry: a header line naming the format
//! and its version, then one `key=value` per line. [`MetaText`] reads it; each format words its
//! own errors around the reasons it returns ("its metadata has no `spp` field", "its metadata
//! field `spp=x` is malformed").

use std::str::FromStr;

/// The `key=value` lines of a metadata text after its header.
#[derive(Debug, Clone)]
pub struct MetaText<'a> {
    fields: Vec<(&'a str, &'a str)>,
}

impl<'a> MetaText<'a> {
    /// The fields of `text` when its first line is `header` (`None` otherwise). Lines without
    /// `=` are skipped; a key given twice reads as its first value.
    #[must_use]
    pub fn parse(text: &'a str, header: &str) -> Option<Self> {
        let mut lines = text.lines();
        (lines.next() == Some(header)).then(|| Self {
            fields: lines.filter_map(|l| l.split_once('=')).collect(),
        })
    }

    /// The value of `key`.
    ///
    /// # Errors
    /// The reason, when the text has no such field.
    pub fn get(&self, key: &str) -> Result<&'a str, String> {
        self.fields
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("its metadata has no `{key}` field"))
    }

    /// The value of `key` read as a `T` (a number, usually).
    ///
    /// # Errors
    /// The reason, when the field is missing or does not read as a `T`.
    pub fn parsed<T: FromStr>(&self, key: &str) -> Result<T, String> {
        let v = self.get(key)?;
        v.parse().map_err(|_| malformed(key, v))
    }

    /// The fields whose key starts with `prefix`, the prefix removed, in file order.
    #[must_use]
    pub fn prefixed(&self, prefix: &str) -> Vec<(String, String)> {
        self.fields
            .iter()
            .filter_map(|(k, v)| Some((k.strip_prefix(prefix)?.to_string(), v.to_string())))
            .collect()
    }
}

/// The reason for a field `key=value` whose value does not read.
#[must_use]
pub fn malformed(key: &str, value: &str) -> String {
    format!("its metadata field `{key}={value}` is malformed")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_read_after_the_header_and_errors_name_the_field() {
        let text = "fmt 1\nspp=8\nbad=x\nset.a=1\nnoequals\nset.b=c=d\n";
        assert!(MetaText::parse(text, "fmt 2").is_none());
        let m = MetaText::parse(text, "fmt 1").expect("header");
        assert_eq!(m.parsed::<u32>("spp"), Ok(8));
        assert_eq!(
            m.parsed::<u32>("bad"),
            Err("its metadata field `bad=x` is malformed".to_string())
        );
        assert_eq!(
            m.get("seed"),
            Err("its metadata has no `seed` field".to_string())
        );
        assert_eq!(
            m.prefixed("set."),
            [("a".into(), "1".into()), ("b".into(), "c=d".into())]
        );
    }
}

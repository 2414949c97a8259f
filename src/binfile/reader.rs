//! A little-endian reader over a file's bytes that reports truncation instead of panicking.

/// The bytes ended before a field did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the file is truncated")]
pub struct Truncated;

/// Reads little-endian fields from the front of a byte slice, each read advancing past it.
#[derive(Debug, Clone)]
pub struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    /// A reader at the start of `bytes`.
    #[must_use]
    pub fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    /// Bytes read so far.
    #[must_use]
    pub fn position(&self) -> usize {
        self.at
    }

    /// The bytes not read yet.
    #[must_use]
    pub fn rest(&self) -> &'a [u8] {
        &self.bytes[self.at..]
    }

    /// The next `n` bytes.
    ///
    /// # Errors
    /// [`Truncated`] when fewer than `n` remain (nothing is read then).
    pub fn take(&mut self, n: usize) -> Result<&'a [u8], Truncated> {
        let end = self.at.checked_add(n).ok_or(Truncated)?;
        let s = self.bytes.get(self.at..end).ok_or(Truncated)?;
        self.at = end;
        Ok(s)
    }

    /// The next `N` bytes as an array.
    ///
    /// # Errors
    /// [`Truncated`] when fewer than `N` remain.
    pub fn array<const N: usize>(&mut self) -> Result<[u8; N], Truncated> {
        let s = self.take(N)?;
        s.try_into().map_err(|_| Truncated)
    }

    /// The next little-endian `u32`.
    ///
    /// # Errors
    /// [`Truncated`] when fewer than 4 bytes remain.
    pub fn u32(&mut self) -> Result<u32, Truncated> {
        self.array().map(u32::from_le_bytes)
    }

    /// The next little-endian `u64`.
    ///
    /// # Errors
    /// [`Truncated`] when fewer than 8 bytes remain.
    pub fn u64(&mut self) -> Result<u64, Truncated> {
        self.array().map(u64::from_le_bytes)
    }

    /// The next little-endian `i128`.
    ///
    /// # Errors
    /// [`Truncated`] when fewer than 16 bytes remain.
    pub fn i128(&mut self) -> Result<i128, Truncated> {
        self.array().map(i128::from_le_bytes)
    }

    /// The next `f32` (its little-endian bit pattern).
    ///
    /// # Errors
    /// [`Truncated`] when fewer than 4 bytes remain.
    pub fn f32(&mut self) -> Result<f32, Truncated> {
        self.u32().map(f32::from_bits)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_little_endian_fields_in_order_and_reports_truncation() {
        let mut bytes = vec![];
        bytes.extend(0x0102_0304u32.to_le_bytes());
        bytes.extend(0x1122_3344_5566_7788u64.to_le_bytes());
        bytes.extend((-3i128).to_le_bytes());
        bytes.extend(1.5f32.to_bits().to_le_bytes());
        bytes.extend(b"xyz");
        let mut r = Reader::new(&bytes);
        assert_eq!(r.u32(), Ok(0x0102_0304));
        assert_eq!(r.u64(), Ok(0x1122_3344_5566_7788));
        assert_eq!(r.i128(), Ok(-3));
        assert_eq!(r.f32(), Ok(1.5));
        assert_eq!(r.position(), 32);
        assert_eq!(r.u32(), Err(Truncated));
        // A failed read reads nothing.
        assert_eq!(r.rest(), b"xyz");
        assert_eq!(r.take(3), Ok(&b"xyz"[..]));
        assert_eq!(r.take(usize::MAX), Err(Truncated));
        assert!(r.rest().is_empty());
    }
}

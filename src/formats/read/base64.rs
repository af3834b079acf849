//! Base64 decoding (RFC 4648, padding optional, whitespace skipped) for VTK
//! binary data arrays and glTF data URIs.

/// The decoded bytes, or `None` for a character outside the alphabet.
pub fn decode(text: &[u8]) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let mut acc = 0u32;
    let mut bits = 0;
    for &c in text {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            b'=' => break,
            c if c.is_ascii_whitespace() => continue,
            _ => return None,
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    #[test]
    fn known_vectors() {
        assert_eq!(super::decode(b"").unwrap(), b"");
        assert_eq!(super::decode(b"Zg==").unwrap(), b"f");
        assert_eq!(super::decode(b"Zm8=").unwrap(), b"fo");
        assert_eq!(super::decode(b"Zm9vYmFy").unwrap(), b"foobar");
        assert!(super::decode(b"Zm9v!").is_none());
    }
}

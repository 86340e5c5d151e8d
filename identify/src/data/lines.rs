//! File line numbers for CSV records. The csv crate's own line counter skips blank
//! lines and miscounts `\r\n`, so this reader adapter watches the bytes going past
//! and maps a record's start byte to the line an editor would show.

use std::collections::VecDeque;
use std::io::{self, Read};

/// One line of the input: where it starts and where its terminator starts.
#[derive(Clone, Copy, Debug)]
struct Span {
    number: u64,
    start: u64,
    /// Offset of the `\r` or `\n` ending the line; `None` while it has not been seen.
    end: Option<u64>,
}

impl Span {
    fn is_blank(&self) -> bool {
        self.end == Some(self.start)
    }
}

/// A reader that remembers where lines start. Line breaks are `\n`, `\r\n` and a
/// lone `\r`, as for the csv crate. Only the lines at or after the last query are
/// kept, so memory stays small when queries follow the reading.
pub(super) struct LineIndex<R> {
    inner: R,
    offset: u64,
    previous_was_cr: bool,
    lines: VecDeque<Span>,
}

impl<R> LineIndex<R> {
    pub(super) fn new(inner: R) -> Self {
        LineIndex {
            inner,
            offset: 0,
            previous_was_cr: false,
            lines: VecDeque::from([Span {
                number: 1,
                start: 0,
                end: None,
            }]),
        }
    }

    fn scan(&mut self, bytes: &[u8]) {
        for &b in bytes {
            let here = self.offset;
            self.offset += 1;
            if b == b'\n' && self.previous_was_cr {
                // The second half of `\r\n`: the new line starts after it.
                self.previous_was_cr = false;
                if let Some(last) = self.lines.back_mut() {
                    last.start = here + 1;
                }
                continue;
            }
            self.previous_was_cr = b == b'\r';
            if b == b'\r' || b == b'\n' {
                let number = match self.lines.back_mut() {
                    Some(last) => {
                        last.end = Some(here);
                        last.number + 1
                    }
                    None => 1,
                };
                self.lines.push_back(Span {
                    number,
                    start: here + 1,
                    end: None,
                });
            }
        }
    }

    /// The 1-based line of the record the csv crate says starts at `byte`: that
    /// offset may point at blank lines or at the `\n` of a `\r\n` before the
    /// record, so the answer is the first non-blank line that holds a byte at or
    /// after it. Queries must not go backwards.
    pub(super) fn line_of(&mut self, byte: u64) -> u64 {
        while self.lines.len() > 1 && self.lines[1].start <= byte {
            self.lines.pop_front();
        }
        let mut k = 0;
        while let Some(span) = self.lines.get(k) {
            let at_terminator = k == 0 && span.end.is_some_and(|end| byte >= end);
            if !(span.is_blank() || at_terminator) || k + 1 == self.lines.len() {
                return span.number;
            }
            k += 1;
        }
        1
    }
}

impl<R: Read> Read for LineIndex<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.scan(&buf[..n]);
        Ok(n)
    }
}

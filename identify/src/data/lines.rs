//! File line numbers for CSV records. The csv crate's own line counter skips blank
//! lines and miscounts `\r\n`, so this reader adapter watches the bytes going past
//! and maps a record's start byte to the line an editor would show. It also
//! refuses a line longer than [`MAX_LINE_BYTES`] (an unbounded line would be read
//! into memory whole: `/dev/zero`, a binary file), and [`skip_bom`] drops a UTF-8
//! byte order mark at the start of the input.

use std::collections::VecDeque;
use std::fmt;
use std::io::{self, Read};

use super::error::{DataError, MAX_LINE_BYTES};

/// The payload of the `io::Error` a line reader returns for a line longer than
/// [`MAX_LINE_BYTES`]; [`line_error`] turns it into [`DataError::LineTooLong`].
#[derive(Debug)]
pub(super) struct TooLong {
    pub(super) line: u64,
}

impl fmt::Display for TooLong {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {} is longer than {MAX_LINE_BYTES} bytes", self.line)
    }
}

impl std::error::Error for TooLong {}

impl TooLong {
    pub(super) fn into_io(self) -> io::Error {
        io::Error::new(io::ErrorKind::InvalidData, self)
    }
}

/// The [`DataError::LineTooLong`] an `io::Error` of a line reader stands for, if any.
pub(super) fn line_error(e: &io::Error) -> Option<DataError> {
    let too_long = e.get_ref()?.downcast_ref::<TooLong>()?;
    Some(DataError::LineTooLong {
        line: too_long.line,
        limit: MAX_LINE_BYTES,
    })
}

/// `reader` without the UTF-8 byte order mark (`EF BB BF`) it may start with, as
/// editors on Windows write it.
pub(super) fn skip_bom<R: Read>(mut reader: R) -> io::Result<io::Chain<io::Cursor<Vec<u8>>, R>> {
    const BOM: &[u8] = b"\xEF\xBB\xBF";
    let mut start = Vec::with_capacity(BOM.len());
    let mut byte = [0u8; 1];
    while start.len() < BOM.len() && BOM.starts_with(&start) {
        match reader.read(&mut byte) {
            Ok(0) => break,
            Ok(_) => start.push(byte[0]),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    if start == BOM {
        start.clear();
    }
    Ok(io::Cursor::new(start).chain(reader))
}

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
    /// The first line that ended longer than [`MAX_LINE_BYTES`].
    too_long: Option<u64>,
}

impl<R> LineIndex<R> {
    pub(super) fn new(inner: R) -> Self {
        LineIndex {
            inner,
            offset: 0,
            previous_was_cr: false,
            too_long: None,
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
                        if here - last.start > MAX_LINE_BYTES as u64 {
                            self.too_long.get_or_insert(last.number);
                        }
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
        // A line that ended too long, or the line still open once it outgrows the
        // limit (before the csv crate buffers more of it).
        let open = self
            .lines
            .back()
            .filter(|last| last.end.is_none() && self.offset - last.start > MAX_LINE_BYTES as u64);
        if let Some(line) = self.too_long.or(open.map(|last| last.number)) {
            return Err(TooLong { line }.into_io());
        }
        Ok(n)
    }
}

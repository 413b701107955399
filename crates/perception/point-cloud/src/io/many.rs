//! Reading a list of files as one stream, in order, while decoding them in
//! parallel: a survey of many LAZ files is decode-bound (one file decodes
//! on one core), so the files ahead of the one being consumed are decoded
//! by other threads into a bounded buffer.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex};

use super::read::{read_chunks_with, StreamReport};
use crate::{CloudError, Point};

/// What a decoding thread hands over for one file.
enum Piece {
    /// Points, and their rows when asked for.
    Chunk(Vec<Point>, Vec<u8>),
    Done(crate::Result<StreamReport>),
}

/// The files' queues and the points buffered ahead of the consumer.
struct Shared {
    queues: Vec<VecDeque<Piece>>,
    /// Points buffered in queues of files after the one being consumed.
    ahead: usize,
}

/// How [`read_files_in_order`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InOrder {
    /// Most points handed on at a time.
    pub chunk: usize,
    /// Files decoded at once.
    pub threads: usize,
    /// Most points buffered by the files after the one being consumed.
    pub lookahead: usize,
    /// Hand each point's LAS record on too ([`super::read_chunks_with`]).
    pub rows: bool,
}

/// The receiver of [`read_files_in_order`]'s chunks: the file's index, its
/// points, and their LAS rows (empty unless asked for).
pub type FileChunkSink<'a> = &'a mut dyn FnMut(usize, &[Point], &[u8]) -> crate::Result<()>;

/// Reads `paths` as one stream: `on_chunk(file, points, rows)` gets every
/// file's finite points in file order, files in the given order, at most
/// `how.chunk` at a time, less `origin`, exactly as [`read_chunks_with`]
/// file after file would give them (with their LAS rows when `how.rows`
/// is set, else empty rows). Up to `how.threads` files are decoded at
/// once; files after the one being consumed may buffer at most
/// `how.lookahead` points between them (the memory this costs: 12 bytes a
/// point, and a record's bytes with rows). `progress(points, files)` is
/// called as chunks are consumed. An error (a file's, or `on_chunk`'s)
/// stops every thread and is returned.
pub fn read_files_in_order(
    paths: &[PathBuf],
    origin: [f64; 3],
    how: InOrder,
    progress: &mut dyn FnMut(u64, usize),
    on_chunk: FileChunkSink<'_>,
) -> crate::Result<Vec<StreamReport>> {
    let InOrder {
        chunk,
        threads,
        lookahead,
        rows,
    } = how;
    let shared = Mutex::new(Shared {
        queues: (0..paths.len()).map(|_| VecDeque::new()).collect(),
        ahead: 0,
    });
    let ready = Condvar::new(); // a queue got a piece
    let room = Condvar::new(); // the buffer ahead shrank, or the consumer moved on
    let next_file = AtomicUsize::new(0);
    let current = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let lock = || shared.lock().unwrap_or_else(|e| e.into_inner());
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1).min(paths.len().max(1)) {
            scope.spawn(|| loop {
                let f = next_file.fetch_add(1, Ordering::SeqCst);
                if f >= paths.len() || stop.load(Ordering::SeqCst) {
                    return;
                }
                let report = read_chunks_with(
                    &paths[f],
                    origin,
                    chunk,
                    rows,
                    &mut |_, _| {},
                    &mut |points, row_bytes| {
                        let mut s = lock();
                        // Files ahead of the consumer wait for room.
                        while f != current.load(Ordering::SeqCst)
                            && s.ahead + points.len() > lookahead
                            && !stop.load(Ordering::SeqCst)
                        {
                            s = room.wait(s).unwrap_or_else(|e| e.into_inner());
                        }
                        if stop.load(Ordering::SeqCst) {
                            return Err(CloudError::Format {
                                path: paths[f].clone(),
                                what: "reading stopped".into(),
                            });
                        }
                        if f != current.load(Ordering::SeqCst) {
                            s.ahead += points.len();
                        }
                        s.queues[f].push_back(Piece::Chunk(points.to_vec(), row_bytes.to_vec()));
                        ready.notify_all();
                        Ok(())
                    },
                );
                lock().queues[f].push_back(Piece::Done(report));
                ready.notify_all();
            });
        }
        // The consumer, on this thread, file after file.
        let result = (|| {
            let mut reports = Vec::with_capacity(paths.len());
            let mut points = 0u64;
            for f in 0..paths.len() {
                if f > 0 {
                    // This file's buffered points no longer count as ahead.
                    // (The first file's never did: it starts as the current
                    // one, and subtracting its queue underflowed `ahead`
                    // when its reader was quicker than this thread.)
                    let mut s = lock();
                    current.store(f, Ordering::SeqCst);
                    let buffered: usize = s.queues[f]
                        .iter()
                        .map(|p| match p {
                            Piece::Chunk(c, _) => c.len(),
                            Piece::Done(_) => 0,
                        })
                        .sum();
                    s.ahead -= buffered;
                    room.notify_all();
                }
                loop {
                    let piece = {
                        let mut s = lock();
                        loop {
                            if let Some(p) = s.queues[f].pop_front() {
                                break p;
                            }
                            s = ready.wait(s).unwrap_or_else(|e| e.into_inner());
                        }
                    };
                    match piece {
                        Piece::Chunk(c, r) => {
                            on_chunk(f, &c, &r)?;
                            points += c.len() as u64;
                            progress(points, f);
                        }
                        Piece::Done(report) => {
                            reports.push(report?);
                            break;
                        }
                    }
                }
            }
            progress(points, paths.len());
            Ok(reports)
        })();
        if result.is_err() {
            stop.store(true, Ordering::SeqCst);
            let _s = lock();
            room.notify_all();
        }
        result
    })
}

//! Data parallelism for mesh preprocessing: rayon's iterators with the `parallel` feature,
//! the same calls run on one thread without it, so a host can build the library without
//! rayon and the code reads the same either way.

#[cfg(feature = "parallel")]
pub(crate) use rayon::{join, prelude::*};

/// Indices a block of [`in_blocks`] holds.
const BLOCK: usize = 1 << 14;

/// Calls `f` on `0..n` in blocks of [`BLOCK`] indices, each block a call of its own.
///
/// A browser runs a WebAssembly function first as quickly compiled baseline code, and
/// switches to its optimised code at a later call, never within one: a single call looping
/// over a million triangles runs unoptimised to its end, where blocks switch a few blocks
/// in. Natively it costs a call per block.
pub(crate) fn in_blocks(n: usize, mut f: impl FnMut(std::ops::Range<usize>)) {
    #[inline(never)]
    fn block<F: FnMut(std::ops::Range<usize>)>(f: &mut F, range: std::ops::Range<usize>) {
        f(range)
    }
    let mut start = 0;
    while start < n {
        let end = n.min(start + BLOCK);
        block(&mut f, start..end);
        start = end;
    }
}

#[cfg(not(feature = "parallel"))]
pub(crate) use sequential::*;

#[cfg(not(feature = "parallel"))]
mod sequential {
    /// `rayon::join`: `a`, then `b`.
    pub(crate) fn join<A, B, RA, RB>(a: A, b: B) -> (RA, RB)
    where
        A: FnOnce() -> RA,
        B: FnOnce() -> RB,
    {
        (a(), b())
    }

    /// `into_par_iter` as a plain iterator.
    pub(crate) trait IntoParallelIterator: IntoIterator + Sized {
        fn into_par_iter(self) -> Self::IntoIter {
            self.into_iter()
        }
    }
    impl<T: IntoIterator> IntoParallelIterator for T {}

    /// Slice methods of rayon's `ParallelSlice` and `ParallelSliceMut`.
    pub(crate) trait ParallelSlice<T> {
        fn par_iter(&self) -> std::slice::Iter<'_, T>;
        fn par_chunks(&self, size: usize) -> Blocks<'_, T>;
        fn par_sort_unstable(&mut self)
        where
            T: Ord;
        fn par_sort_unstable_by_key<K: Ord, F: Fn(&T) -> K>(&mut self, key: F);
    }
    impl<T> ParallelSlice<T> for [T] {
        fn par_iter(&self) -> std::slice::Iter<'_, T> {
            self.iter()
        }
        fn par_chunks(&self, size: usize) -> Blocks<'_, T> {
            Blocks(self.chunks(size))
        }
        fn par_sort_unstable(&mut self)
        where
            T: Ord,
        {
            self.sort_unstable()
        }
        fn par_sort_unstable_by_key<K: Ord, F: Fn(&T) -> K>(&mut self, key: F) {
            self.sort_unstable_by_key(key)
        }
    }

    /// `par_chunks` on one thread: the chunks, whose `map` calls its function for each chunk
    /// as a call of its own, so that a browser swaps in the function's optimised code after
    /// the first chunks (see [`super::in_blocks`]).
    pub(crate) struct Blocks<'a, T>(std::slice::Chunks<'a, T>);

    impl<'a, T> Blocks<'a, T> {
        pub(crate) fn map<B, F: Fn(&'a [T]) -> B>(
            self,
            f: F,
        ) -> impl Iterator<Item = B> + use<'a, T, B, F> {
            #[inline(never)]
            fn call<A, B, F: Fn(A) -> B>(f: &F, a: A) -> B {
                f(a)
            }
            self.0.map(move |chunk| call(&f, chunk))
        }
    }

    /// rayon's `flat_map_iter`, which is `flat_map` on one thread (used by the drawings and
    /// the tools, not by the pass alone).
    #[allow(dead_code)]
    pub(crate) trait FlatMapIter: Iterator + Sized {
        fn flat_map_iter<U: IntoIterator, F: FnMut(Self::Item) -> U>(
            self,
            f: F,
        ) -> std::iter::FlatMap<Self, U, F> {
            self.flat_map(f)
        }
    }
    impl<I: Iterator> FlatMapIter for I {}
}

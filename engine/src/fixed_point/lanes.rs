//! Lanes of unsigned 64-bit integers: the few operations the fixed-point kernel
//! ([`super::kernel`]) needs, for one sPLL per lane, in a portable scalar form (one lane) and
//! with AVX-512 (eight lanes, x86-64 only).
//!
//! Every operation is exact integer arithmetic on values below `2^63`, so each implementation
//! gives the same result lane by lane; the kernel is written once over [`Lanes`].
//!
//! The AVX-512 implementation calls `std::arch` intrinsics, which are `unsafe` outside a
//! function compiled for AVX-512F. Its methods are `#[inline(always)]` and only ever run
//! inside [`super::kernel`]'s `#[target_feature(enable = "avx512f")]` entry point, which is
//! only called after `is_x86_feature_detected!("avx512f")` returned true: that is the safety
//! argument of every `unsafe` block below.

/// Operations on `N` lanes of `u64`. Arguments of [`Lanes::mul32`] must be below `2^32`, shift
/// counts below 64, and values compared with [`Lanes::gt`] below `2^63`.
pub(super) trait Lanes: Copy {
    /// Number of lanes.
    const N: usize;
    /// One bit per lane (the result of a comparison).
    type Mask: Copy;

    /// Every lane `x`.
    fn splat(x: u64) -> Self;
    /// Lanes from `a[..N]` (`a.len() >= N`).
    fn load(a: &[u64]) -> Self;
    /// Lanes into `a[..N]` (`a.len() >= N`).
    fn store(self, a: &mut [u64]);
    /// Lane-wise `self + o` (no overflow: operands stay below `2^63`).
    fn add(self, o: Self) -> Self;
    /// Lane-wise product of the low 32 bits of each operand, as a 64-bit value.
    fn mul32(self, o: Self) -> Self;
    /// Lane-wise logical right shift by `by` (each count below 64).
    fn shr(self, by: Self) -> Self;
    /// Lane-wise minimum.
    fn min(self, o: Self) -> Self;
    /// Lane-wise `self > o`.
    fn gt(self, o: Self) -> Self::Mask;
    /// `self + o` where `m` is set, 0 elsewhere.
    fn add_or_zero(self, o: Self, m: Self::Mask) -> Self;
    /// `self` where `m` is set, 0 elsewhere.
    fn zero_unless(self, m: Self::Mask) -> Self;
    /// `self` where `m` is clear, 0 elsewhere.
    fn zero_if(self, m: Self::Mask) -> Self;
    /// `o` where `m` is set, `self` elsewhere.
    fn replace(self, m: Self::Mask, o: Self) -> Self;
    /// Bit `l` set iff lane `l` is set.
    fn bits(m: Self::Mask) -> u32;
    /// No lane set.
    fn none() -> Self::Mask;
}

/// One lane: the portable fallback, plain `u64` arithmetic.
#[derive(Clone, Copy, Debug)]
pub(super) struct Scalar(u64);

impl Lanes for Scalar {
    const N: usize = 1;
    type Mask = bool;

    #[inline(always)]
    fn splat(x: u64) -> Self {
        Scalar(x)
    }
    #[inline(always)]
    fn load(a: &[u64]) -> Self {
        Scalar(a[0])
    }
    #[inline(always)]
    fn store(self, a: &mut [u64]) {
        a[0] = self.0;
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Scalar(self.0 + o.0)
    }
    #[inline(always)]
    fn mul32(self, o: Self) -> Self {
        Scalar(u64::from(self.0 as u32) * u64::from(o.0 as u32))
    }
    #[inline(always)]
    fn shr(self, by: Self) -> Self {
        Scalar(self.0 >> by.0)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Scalar(self.0.min(o.0))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self.0 > o.0
    }
    #[inline(always)]
    fn add_or_zero(self, o: Self, m: bool) -> Self {
        Scalar(if m { self.0 + o.0 } else { 0 })
    }
    #[inline(always)]
    fn zero_unless(self, m: bool) -> Self {
        Scalar(if m { self.0 } else { 0 })
    }
    #[inline(always)]
    fn zero_if(self, m: bool) -> Self {
        Scalar(if m { 0 } else { self.0 })
    }
    #[inline(always)]
    fn replace(self, m: bool, o: Self) -> Self {
        if m {
            o
        } else {
            self
        }
    }
    #[inline(always)]
    fn bits(m: bool) -> u32 {
        u32::from(m)
    }
    #[inline(always)]
    fn none() -> bool {
        false
    }
}

#[cfg(target_arch = "x86_64")]
pub(super) use avx512::Avx512;

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::Lanes;
    use std::arch::x86_64::{
        __m512i, __mmask8, _mm512_add_epi64, _mm512_cmpgt_epu64_mask, _mm512_loadu_epi64,
        _mm512_mask_mov_epi64, _mm512_maskz_add_epi64, _mm512_maskz_mov_epi64, _mm512_min_epu64,
        _mm512_mul_epu32, _mm512_set1_epi64, _mm512_setzero_si512, _mm512_srlv_epi64,
        _mm512_storeu_epi64,
    };

    /// Eight lanes in one AVX-512 register (see the module docs for the safety argument).
    #[derive(Clone, Copy, Debug)]
    pub(in crate::fixed_point) struct Avx512(__m512i);

    impl Lanes for Avx512 {
        const N: usize = 8;
        type Mask = __mmask8;

        #[inline(always)]
        fn splat(x: u64) -> Self {
            // SAFETY: AVX-512F is available (module docs); the cast keeps the bits.
            Avx512(unsafe { _mm512_set1_epi64(x as i64) })
        }
        #[inline(always)]
        fn load(a: &[u64]) -> Self {
            assert!(a.len() >= Self::N);
            // SAFETY: AVX-512F is available; `a` holds at least 8 values (asserted), the load
            // is unaligned.
            Avx512(unsafe { _mm512_loadu_epi64(a.as_ptr().cast()) })
        }
        #[inline(always)]
        fn store(self, a: &mut [u64]) {
            assert!(a.len() >= Self::N);
            // SAFETY: AVX-512F is available; `a` has room for 8 values (asserted), the store
            // is unaligned.
            unsafe { _mm512_storeu_epi64(a.as_mut_ptr().cast(), self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            // SAFETY: AVX-512F is available (module docs).
            Avx512(unsafe { _mm512_add_epi64(self.0, o.0) })
        }
        #[inline(always)]
        fn mul32(self, o: Self) -> Self {
            // SAFETY: AVX-512F is available (module docs).
            Avx512(unsafe { _mm512_mul_epu32(self.0, o.0) })
        }
        #[inline(always)]
        fn shr(self, by: Self) -> Self {
            // SAFETY: AVX-512F is available (module docs).
            Avx512(unsafe { _mm512_srlv_epi64(self.0, by.0) })
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            // SAFETY: AVX-512F is available (module docs).
            Avx512(unsafe { _mm512_min_epu64(self.0, o.0) })
        }
        #[inline(always)]
        fn gt(self, o: Self) -> __mmask8 {
            // SAFETY: AVX-512F is available (module docs).
            unsafe { _mm512_cmpgt_epu64_mask(self.0, o.0) }
        }
        #[inline(always)]
        fn add_or_zero(self, o: Self, m: __mmask8) -> Self {
            // SAFETY: AVX-512F is available (module docs).
            Avx512(unsafe { _mm512_maskz_add_epi64(m, self.0, o.0) })
        }
        #[inline(always)]
        fn zero_unless(self, m: __mmask8) -> Self {
            // SAFETY: AVX-512F is available (module docs).
            Avx512(unsafe { _mm512_maskz_mov_epi64(m, self.0) })
        }
        #[inline(always)]
        fn zero_if(self, m: __mmask8) -> Self {
            // SAFETY: AVX-512F is available (module docs).
            Avx512(unsafe { _mm512_mask_mov_epi64(self.0, m, _mm512_setzero_si512()) })
        }
        #[inline(always)]
        fn replace(self, m: __mmask8, o: Self) -> Self {
            // SAFETY: AVX-512F is available (module docs).
            Avx512(unsafe { _mm512_mask_mov_epi64(self.0, m, o.0) })
        }
        #[inline(always)]
        fn bits(m: __mmask8) -> u32 {
            u32::from(m)
        }
        #[inline(always)]
        fn none() -> __mmask8 {
            0
        }
    }
}

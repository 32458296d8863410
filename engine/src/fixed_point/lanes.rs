//! Lanes of unsigned 64-bit integers: the few operations the fixed-point kernel
//! ([`super::kernel`]) needs, for one sPLL per lane, in a portable scalar form (one lane), with
//! AVX-512 (eight lanes) or AVX2 (four lanes, x86-64 only) and as a [`Pair`] of any of them.
//!
//! Every operation is exact integer arithmetic on values below `2^63`, so each implementation
//! gives the same result lane by lane; the kernel is written once over [`Lanes`].
//!
//! The AVX-512 implementation calls `std::arch` intrinsics, which are `unsafe` outside a
//! function compiled for AVX-512F. Its methods are `#[inline(always)]` and only ever run
//! inside [`super::kernel`]'s `#[target_feature(enable = "avx512f")]` entry points, which are
//! only called after `is_x86_feature_detected!("avx512f")` returned true (and, for
//! `Avx512<true>`, `#[target_feature(enable = "avx512f,avx512ifma")]` ones called after
//! `is_x86_feature_detected!("avx512ifma")` too); likewise the AVX2 implementation runs only
//! inside `#[target_feature(enable = "avx2")]` entry points called after
//! `is_x86_feature_detected!("avx2")`: that is the safety argument of every `unsafe` block
//! below.

/// Operations on `N` lanes of `u64`. Arguments of [`Lanes::mul32`] must be below `2^32`, shift
/// counts below 64, and values compared with [`Lanes::gt`] below `2^63`.
pub(super) trait Lanes: Copy {
    /// Number of lanes.
    const N: usize;
    /// One bit per lane (the result of a comparison).
    type Mask: Copy;
    /// Decay factors prepared by [`Lanes::keep`].
    type Keep: Copy;

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
    /// One step of decay, `(self · keep) >> decay_bits` lane by lane (`self < 2^31`).
    fn decay(self, keep: Self::Keep) -> Self;
    /// `decay(self) + o` where `m` is set, 0 elsewhere.
    fn decay_add_or_zero(self, keep: Self::Keep, o: Self, m: Self::Mask) -> Self;
    /// The decay factors `keep = 2^decay_bits − δ` of every lane (each at most
    /// `2^decay_bits`) in the form [`Lanes::decay`] uses.
    fn keep(keep: Self, decay_bits: u32) -> Self::Keep;
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
}

/// One lane: the portable fallback, plain `u64` arithmetic.
#[derive(Clone, Copy, Debug)]
pub(super) struct Scalar(u64);

impl Lanes for Scalar {
    const N: usize = 1;
    type Mask = bool;
    type Keep = (u64, u32);

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
    fn decay(self, (keep, bits): (u64, u32)) -> Self {
        self.mul32(Scalar(keep)).shr(Scalar(u64::from(bits)))
    }
    #[inline(always)]
    fn decay_add_or_zero(self, keep: (u64, u32), o: Self, m: bool) -> Self {
        self.decay(keep).add_or_zero(o, m)
    }
    #[inline(always)]
    fn keep(keep: Self, decay_bits: u32) -> (u64, u32) {
        (keep.0, decay_bits)
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
}

#[cfg(target_arch = "x86_64")]
pub(super) use avx512::Avx512;

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::Lanes;
    use std::arch::x86_64::{
        __m128i, __m512i, __mmask8, _mm512_add_epi64, _mm512_cmpgt_epu64_mask, _mm512_loadu_epi64,
        _mm512_madd52hi_epu64, _mm512_mask_mov_epi64, _mm512_maskz_add_epi64,
        _mm512_maskz_madd52hi_epu64, _mm512_maskz_mov_epi64, _mm512_min_epu64, _mm512_mul_epu32,
        _mm512_set1_epi64, _mm512_setzero_si512, _mm512_sll_epi64, _mm512_srl_epi64,
        _mm512_srlv_epi64, _mm512_storeu_epi64, _mm_cvtsi32_si128,
    };

    /// Eight lanes in one AVX-512 register (see the module docs for the safety argument).
    ///
    /// With `IFMA`, a decay is one 52-bit multiply-add (AVX-512 IFMA) instead of a multiply
    /// and a shift: `(x · keep) >> D = (x · (keep << (52 − D))) >> 52`, exact for `x < 2^52`,
    /// which needs `keep << (52 − D) < 2^52`, i.e. every decay constant `δ >= 1`. Only then,
    /// and on a CPU with AVX-512 IFMA, is `Avx512<true>` used (see `super::kernel`).
    #[derive(Clone, Copy, Debug)]
    pub(in crate::fixed_point) struct Avx512<const IFMA: bool>(__m512i);

    impl<const IFMA: bool> Lanes for Avx512<IFMA> {
        const N: usize = 8;
        type Mask = __mmask8;
        /// With `IFMA` `keep << (52 − D)`, otherwise `keep` and the shift count `D`.
        type Keep = (__m512i, __m128i);

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
        fn decay(self, (keep, bits): Self::Keep) -> Self {
            if IFMA {
                // SAFETY: AVX-512F and AVX-512 IFMA are available (type docs).
                Avx512(unsafe { _mm512_madd52hi_epu64(_mm512_setzero_si512(), self.0, keep) })
            } else {
                // SAFETY: AVX-512F is available (module docs).
                Avx512(unsafe { _mm512_srl_epi64(_mm512_mul_epu32(self.0, keep), bits) })
            }
        }
        #[inline(always)]
        fn decay_add_or_zero(self, (keep, bits): Self::Keep, o: Self, m: __mmask8) -> Self {
            if IFMA {
                // SAFETY: AVX-512F and AVX-512 IFMA are available (type docs).
                Avx512(unsafe { _mm512_maskz_madd52hi_epu64(m, o.0, self.0, keep) })
            } else {
                self.decay((keep, bits)).add_or_zero(o, m)
            }
        }
        #[inline(always)]
        fn keep(keep: Self, decay_bits: u32) -> Self::Keep {
            // SAFETY: AVX-512F is available (module docs).
            unsafe {
                let bits = _mm_cvtsi32_si128(decay_bits as i32);
                if IFMA {
                    let to_52 = _mm_cvtsi32_si128(52 - decay_bits as i32);
                    (_mm512_sll_epi64(keep.0, to_52), bits)
                } else {
                    (keep.0, bits)
                }
            }
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
    }
}

#[cfg(target_arch = "x86_64")]
pub(super) use avx2::Avx2;

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::Lanes;
    use std::arch::x86_64::{
        __m256i, _mm256_add_epi64, _mm256_and_si256, _mm256_andnot_si256, _mm256_blendv_epi8,
        _mm256_castsi256_pd, _mm256_cmpgt_epi64, _mm256_loadu_si256, _mm256_movemask_pd,
        _mm256_mul_epu32, _mm256_set1_epi64x, _mm256_srlv_epi64, _mm256_storeu_si256,
    };

    /// Four lanes in one AVX2 register (see the module docs for the safety argument).
    ///
    /// AVX2 has no unsigned 64-bit comparison, minimum or masked moves: the kernel's values
    /// stay below `2^63` (the [`Lanes`] contract), where the signed comparison agrees with
    /// the unsigned one, and a mask is a register of all-ones or all-zeros lanes.
    #[derive(Clone, Copy, Debug)]
    pub(in crate::fixed_point) struct Avx2(__m256i);

    impl Lanes for Avx2 {
        const N: usize = 4;
        type Mask = __m256i;
        /// `keep` and the shift count `D` in every lane.
        type Keep = (__m256i, __m256i);

        #[inline(always)]
        fn splat(x: u64) -> Self {
            // SAFETY: AVX2 is available (module docs); the cast keeps the bits.
            Avx2(unsafe { _mm256_set1_epi64x(x as i64) })
        }
        #[inline(always)]
        fn load(a: &[u64]) -> Self {
            assert!(a.len() >= Self::N);
            // SAFETY: AVX2 is available; `a` holds at least 4 values (asserted), the load is
            // unaligned.
            Avx2(unsafe { _mm256_loadu_si256(a.as_ptr().cast()) })
        }
        #[inline(always)]
        fn store(self, a: &mut [u64]) {
            assert!(a.len() >= Self::N);
            // SAFETY: AVX2 is available; `a` has room for 4 values (asserted), the store is
            // unaligned.
            unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), self.0) }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            // SAFETY: AVX2 is available (module docs).
            Avx2(unsafe { _mm256_add_epi64(self.0, o.0) })
        }
        #[inline(always)]
        fn mul32(self, o: Self) -> Self {
            // SAFETY: AVX2 is available (module docs).
            Avx2(unsafe { _mm256_mul_epu32(self.0, o.0) })
        }
        #[inline(always)]
        fn shr(self, by: Self) -> Self {
            // SAFETY: AVX2 is available (module docs).
            Avx2(unsafe { _mm256_srlv_epi64(self.0, by.0) })
        }
        #[inline(always)]
        fn decay(self, (keep, bits): Self::Keep) -> Self {
            self.mul32(Avx2(keep)).shr(Avx2(bits))
        }
        #[inline(always)]
        fn decay_add_or_zero(self, keep: Self::Keep, o: Self, m: __m256i) -> Self {
            self.decay(keep).add_or_zero(o, m)
        }
        #[inline(always)]
        fn keep(keep: Self, decay_bits: u32) -> Self::Keep {
            (keep.0, Self::splat(u64::from(decay_bits)).0)
        }
        #[inline(always)]
        fn min(self, o: Self) -> Self {
            o.replace(o.gt(self), self)
        }
        #[inline(always)]
        fn gt(self, o: Self) -> __m256i {
            // SAFETY: AVX2 is available (module docs); both operands are below 2^63, where
            // the signed comparison is the unsigned one.
            unsafe { _mm256_cmpgt_epi64(self.0, o.0) }
        }
        #[inline(always)]
        fn add_or_zero(self, o: Self, m: __m256i) -> Self {
            self.add(o).zero_unless(m)
        }
        #[inline(always)]
        fn zero_unless(self, m: __m256i) -> Self {
            // SAFETY: AVX2 is available (module docs).
            Avx2(unsafe { _mm256_and_si256(m, self.0) })
        }
        #[inline(always)]
        fn zero_if(self, m: __m256i) -> Self {
            // SAFETY: AVX2 is available (module docs).
            Avx2(unsafe { _mm256_andnot_si256(m, self.0) })
        }
        #[inline(always)]
        fn replace(self, m: __m256i, o: Self) -> Self {
            // SAFETY: AVX2 is available (module docs); every mask lane is all ones or zeros.
            Avx2(unsafe { _mm256_blendv_epi8(self.0, o.0, m) })
        }
        #[inline(always)]
        fn bits(m: __m256i) -> u32 {
            // SAFETY: AVX2 is available (module docs); the sign bit of each lane is its flag.
            unsafe { _mm256_movemask_pd(_mm256_castsi256_pd(m)) as u32 }
        }
    }
}

/// Two sets of lanes stepped side by side: twice the lanes, and two independent dependency
/// chains per step for the CPU to overlap.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pair<V>(V, V);

impl<V: Lanes> Lanes for Pair<V> {
    const N: usize = 2 * V::N;
    type Mask = (V::Mask, V::Mask);
    type Keep = (V::Keep, V::Keep);

    #[inline(always)]
    fn splat(x: u64) -> Self {
        Pair(V::splat(x), V::splat(x))
    }
    #[inline(always)]
    fn load(a: &[u64]) -> Self {
        Pair(V::load(a), V::load(&a[V::N..]))
    }
    #[inline(always)]
    fn store(self, a: &mut [u64]) {
        self.0.store(a);
        self.1.store(&mut a[V::N..]);
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Pair(self.0.add(o.0), self.1.add(o.1))
    }
    #[inline(always)]
    fn mul32(self, o: Self) -> Self {
        Pair(self.0.mul32(o.0), self.1.mul32(o.1))
    }
    #[inline(always)]
    fn shr(self, by: Self) -> Self {
        Pair(self.0.shr(by.0), self.1.shr(by.1))
    }
    #[inline(always)]
    fn decay(self, keep: Self::Keep) -> Self {
        Pair(self.0.decay(keep.0), self.1.decay(keep.1))
    }
    #[inline(always)]
    fn decay_add_or_zero(self, keep: Self::Keep, o: Self, m: Self::Mask) -> Self {
        Pair(
            self.0.decay_add_or_zero(keep.0, o.0, m.0),
            self.1.decay_add_or_zero(keep.1, o.1, m.1),
        )
    }
    #[inline(always)]
    fn keep(keep: Self, decay_bits: u32) -> Self::Keep {
        (V::keep(keep.0, decay_bits), V::keep(keep.1, decay_bits))
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Pair(self.0.min(o.0), self.1.min(o.1))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Self::Mask {
        (self.0.gt(o.0), self.1.gt(o.1))
    }
    #[inline(always)]
    fn add_or_zero(self, o: Self, m: Self::Mask) -> Self {
        Pair(self.0.add_or_zero(o.0, m.0), self.1.add_or_zero(o.1, m.1))
    }
    #[inline(always)]
    fn zero_unless(self, m: Self::Mask) -> Self {
        Pair(self.0.zero_unless(m.0), self.1.zero_unless(m.1))
    }
    #[inline(always)]
    fn zero_if(self, m: Self::Mask) -> Self {
        Pair(self.0.zero_if(m.0), self.1.zero_if(m.1))
    }
    #[inline(always)]
    fn replace(self, m: Self::Mask, o: Self) -> Self {
        Pair(self.0.replace(m.0, o.0), self.1.replace(m.1, o.1))
    }
    #[inline(always)]
    fn bits(m: Self::Mask) -> u32 {
        V::bits(m.0) | V::bits(m.1) << V::N
    }
}

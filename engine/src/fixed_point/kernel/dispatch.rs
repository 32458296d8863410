//! Which implementation of [`Lanes`] runs the step loop on this CPU ([`Kernel`]), and the
//! copies of [`run_block`] and [`advance`] compiled for each instruction set it may pick.
//!
//! A copy compiled for target features is `unsafe` to call: [`Kernel::detect`] (or
//! `Kernel::available` in tests) names an implementation only after the CPU was found to
//! support its features, and [`Kernel::run`] calls only that implementation's copies.

#[cfg(target_arch = "x86_64")]
use crate::fixed_point::lanes::{Avx2, Avx512, Pair};
use crate::fixed_point::lanes::{Lanes, Scalar};
use crate::fixed_point::{FixedRecord, FixedSpll, FixedState};

use super::{advance, run_block, BlockRun, Constants, Progress, Spikes, SPIKE_BUFFER};

/// Which implementation of [`Lanes`] runs the step loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::fixed_point) enum Kernel {
    /// One sPLL at a time, plain integer arithmetic (any CPU).
    Scalar,
    /// Sixteen sPLLs in two AVX-512 registers; only constructed (by [`Kernel::detect`], or
    /// `Kernel::available` in tests) after the CPU was found to support AVX-512F.
    #[cfg(target_arch = "x86_64")]
    Avx512,
    /// As [`Kernel::Avx512`], with decays by AVX-512 IFMA multiply-adds in blocks whose decay
    /// constants are all non-zero; only constructed (as [`Kernel::Avx512`]) after the CPU was
    /// found to support AVX-512F and AVX-512 IFMA.
    #[cfg(target_arch = "x86_64")]
    Avx512Ifma,
    /// Eight sPLLs in two AVX2 registers, for CPUs without AVX-512; only constructed after the
    /// CPU was found to support AVX2.
    #[cfg(target_arch = "x86_64")]
    Avx2,
}

impl Kernel {
    /// The fastest implementation this CPU supports.
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx512f") {
            if std::is_x86_feature_detected!("avx512ifma") {
                return Kernel::Avx512Ifma;
            }
            return Kernel::Avx512;
        }
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            return Kernel::Avx2;
        }
        Kernel::Scalar
    }

    /// Every implementation this CPU supports.
    #[cfg(test)]
    pub fn available() -> Vec<Self> {
        let mut all = vec![Kernel::Scalar];
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            all.push(Kernel::Avx2);
        }
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx512f") {
            all.push(Kernel::Avx512);
            if std::is_x86_feature_detected!("avx512ifma") {
                all.push(Kernel::Avx512Ifma);
            }
        }
        all
    }

    /// sPLLs per block.
    pub fn lanes(self) -> usize {
        match self {
            Kernel::Scalar => Scalar::N,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 | Kernel::Avx512Ifma => Pair::<Avx512<false>>::N,
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => Pair::<Avx2>::N,
        }
    }

    /// Run a block of at most [`Kernel::lanes`] sPLLs for steps `run.start_step + 1 ..=
    /// run.n_steps` from the states `start` (one per sPLL of `block`, saved after step
    /// `run.start_step`; empty: from rest); `dt` [s] only scales the recorded spike times. One
    /// record per sPLL of `block`.
    pub fn run(
        self,
        block: &[FixedSpll],
        start: &[FixedState],
        run: &BlockRun<'_>,
    ) -> Vec<FixedRecord> {
        match self {
            Kernel::Scalar => run_block::<Scalar>(block, start, run, |c, p, spikes| {
                advance_scalar(c, p, run, spikes)
            }),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `Kernel::Avx512` is only constructed when the CPU supports AVX-512F.
            Kernel::Avx512 => unsafe { run_avx512(block, start, run) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `Kernel::Avx2` is only constructed when the CPU supports AVX2.
            Kernel::Avx2 => unsafe { run_avx2(block, start, run) },
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512Ifma => {
                let decays = |p: &FixedSpll| {
                    [
                        p.cco_syn_decay,
                        p.cco_decay,
                        p.fac_decay,
                        p.trg_decay,
                        p.tde_decay,
                    ]
                };
                if block.iter().flat_map(decays).all(|d| d > 0) {
                    // SAFETY: `Kernel::Avx512Ifma` is only constructed when the CPU supports
                    // AVX-512F and AVX-512 IFMA; every decay constant is non-zero.
                    unsafe { run_avx512_ifma(block, start, run) }
                } else {
                    // SAFETY: as above (AVX-512F).
                    unsafe { run_avx512(block, start, run) }
                }
            }
        }
    }
}

/// Defines `$name`, [`run_block`] with the attributes given (the target features it is compiled
/// for, and its docs): one register of `$lanes` for a block that fits it, a [`Pair`] of them
/// otherwise, each stepped by `$advance` (compiled for the same features). `$name` is unsafe:
/// the CPU must support its target features, and `block` must meet what `$advance` asks of it.
#[cfg(target_arch = "x86_64")]
macro_rules! run_with_lanes {
    ($(#[$attr:meta])* $name:ident, $advance:ident, $lanes:ty) => {
        $(#[$attr])*
        unsafe fn $name(
            block: &[FixedSpll],
            start: &[FixedState],
            run: &BlockRun<'_>,
        ) -> Vec<FixedRecord> {
            // SAFETY (both): `$name` only runs on a CPU with the target features it is compiled
            // for, which `$advance` is compiled for too, on blocks that meet `$advance`'s
            // contract (its own contract).
            if block.len() <= <$lanes>::N {
                run_block(block, start, run, |c, p, spikes| unsafe {
                    $advance::<$lanes>(c, p, run, spikes)
                })
            } else {
                run_block(block, start, run, |c, p, spikes| unsafe {
                    $advance::<Pair<$lanes>>(c, p, run, spikes)
                })
            }
        }
    };
}

/// Defines `$name`, [`advance`] with the attributes given (the target features it is compiled
/// for, and its docs), kept out of line: as a function of its own the step loop is a plain loop,
/// whose state the register allocator keeps in registers. `unsafe fn` for one compiled for
/// target features (the CPU must support them), `fn` for one that runs on any CPU.
macro_rules! advance_out_of_line {
    ($(#[$attr:meta])* fn $name:ident) => {
        advance_out_of_line!(@ [$(#[$attr])*] [] $name);
    };
    ($(#[$attr:meta])* unsafe fn $name:ident) => {
        advance_out_of_line!(@ [$(#[$attr])*] [unsafe] $name);
    };
    (@ [$($attr:tt)*] [$($unsafe:tt)*] $name:ident) => {
        $($attr)*
        #[inline(never)]
        $($unsafe)* fn $name<V: Lanes>(
            c: &Constants<V>,
            p: &mut Progress<V>,
            run: &BlockRun<'_>,
            spikes: &mut [Spikes; SPIKE_BUFFER],
        ) -> usize {
            advance(c, p, run, spikes)
        }
    };
}

#[cfg(target_arch = "x86_64")]
run_with_lanes!(
    /// [`run_block`] compiled for AVX-512F: one register for a block of up to eight sPLLs (the
    /// last one of a network, often), a [`Pair`] otherwise.
    ///
    /// # Safety
    /// The CPU must support AVX-512F.
    #[target_feature(enable = "avx512f")]
    run_avx512,
    advance_avx512,
    Avx512<false>
);

#[cfg(target_arch = "x86_64")]
run_with_lanes!(
    /// [`run_avx512`] with IFMA decays, compiled for AVX-512F and AVX-512 IFMA.
    ///
    /// # Safety
    /// The CPU must support AVX-512F and AVX-512 IFMA, and every decay constant of `block`
    /// must be non-zero.
    #[target_feature(enable = "avx512f,avx512ifma")]
    run_avx512_ifma,
    advance_avx512_ifma,
    Avx512<true>
);

#[cfg(target_arch = "x86_64")]
run_with_lanes!(
    /// [`run_block`] compiled for AVX2: one register for a block of up to four sPLLs, a
    /// [`Pair`] otherwise.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[target_feature(enable = "avx2")]
    run_avx2,
    advance_avx2,
    Avx2
);

#[cfg(target_arch = "x86_64")]
advance_out_of_line!(
    /// [`advance`] compiled for AVX2 (`V`: `Avx2` or a `Pair` of it).
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn advance_avx2
);

#[cfg(target_arch = "x86_64")]
advance_out_of_line!(
    /// [`advance`] compiled for AVX-512F (`V`: `Avx512<false>` or a `Pair` of it).
    ///
    /// # Safety
    /// The CPU must support AVX-512F.
    #[target_feature(enable = "avx512f")]
    unsafe fn advance_avx512
);

#[cfg(target_arch = "x86_64")]
advance_out_of_line!(
    /// [`advance_avx512`] for `Avx512<true>` lanes (or a `Pair` of them), compiled for
    /// AVX-512F and AVX-512 IFMA.
    ///
    /// # Safety
    /// The CPU must support AVX-512F and AVX-512 IFMA.
    #[target_feature(enable = "avx512f,avx512ifma")]
    unsafe fn advance_avx512_ifma
);

advance_out_of_line!(
    /// [`advance`] for one lane (`V`: [`Scalar`]), on any CPU.
    fn advance_scalar
);

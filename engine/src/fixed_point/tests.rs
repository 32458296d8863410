//! Unit tests of the fixed-point reference: worked cases, every step-loop implementation against
//! the plain scalar reference, and the checks of every input.

use super::reference::{decay, reference_run};
use super::*;

const DT: f64 = 1e-4;

fn format() -> FixedFormat {
    FixedFormat::new(24, 12).unwrap()
}

/// A row with no decays, no refractory periods, silent TDE (threshold at the maximum),
/// with the named parameters changed.
fn row(changes: &[(&str, i64)]) -> [i64; N_FIXED_PARAMS] {
    let mut r = [0; N_FIXED_PARAMS];
    let mut set = |name: &str, value: i64| {
        let k = FIXED_PARAM_NAMES.iter().position(|n| *n == name).unwrap();
        r[k] = value;
    };
    set("cco_threshold", 1000);
    set("tde_threshold", format().state_max() - 1);
    for &(name, value) in changes {
        set(name, value);
    }
    r
}

fn spll(row: [i64; N_FIXED_PARAMS]) -> FixedSpll {
    FixedSpll::from_row(&row, 0, &format()).unwrap()
}

fn config(duration: f64) -> StepConfig<'static> {
    StepConfig {
        dt: DT,
        duration,
        start_step: 0,
        starts: &[],
        keep_spikes: true,
        max_steps: MAX_STEPS,
        cancel: &NEVER,
    }
}

fn run(row: [i64; N_FIXED_PARAMS], inputs: &[f64], steps: u64) -> FixedRecord {
    let out = simulate_fixed(
        &[spll(row)],
        &format(),
        &[inputs],
        config(steps as f64 * DT),
        Some(1),
    )
    .unwrap();
    out.into_iter().next().unwrap().into_iter().next().unwrap()
}

#[test]
fn a_spike_on_a_step_end_arrives_in_that_step() {
    // 0.49 ms / 10 us = 49.00000000000001 in floating point: still step 49.
    let dt = 1e-5;
    for k in 1..20_000u64 {
        let t = k as f64 * dt;
        assert_eq!(spike_step(t, dt), k, "t = {t:e}");
        assert_eq!(spike_step(f64::from_bits(t.to_bits() + 1), dt), k);
        assert_eq!(spike_step((k as f64 - 0.5) * dt, dt), k);
        assert_eq!(spike_step((k as f64 + 1e-6) * dt, dt), k + 1);
    }
    assert_eq!(spike_step(0.0, dt), 1);
}

#[test]
fn decay_is_multiply_and_truncating_shift() {
    assert_eq!(decay(1000, 4096 - 2048, 12), 500);
    assert_eq!(decay(1001, 4096 - 2048, 12), 500);
    assert_eq!(decay(7, 4095, 12), 6, "(7 * 4095) >> 12 = 6.998 truncated");
    assert_eq!(decay(5, 4096, 12), 5, "delta 0: no decay");
    assert_eq!(decay(5, 0, 12), 0, "delta 2^D: cleared in one step");
}

#[test]
fn free_running_cco_without_leak_has_the_closed_form_period() {
    // v_j = j * bias exceeds the threshold first at j = floor(theta / bias) + 1, then the
    // refractory period holds it R steps: period R + floor(theta/bias) + 1 steps.
    let r = row(&[("cco_bias", 70), ("cco_refr", 9), ("cco_threshold", 1000)]);
    let rec = run(r, &[], 500);
    let first = 1000 / 70 + 1;
    let period = 9 + first;
    let expected: Vec<f64> = (0..)
        .map(|j| (first + j * period) as f64 * DT)
        .take_while(|&t| t <= 500.0 * DT + 1e-12)
        .collect();
    assert_eq!(rec.cco_spikes.len(), expected.len());
    for (got, want) in rec.cco_spikes.iter().zip(&expected) {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    assert_eq!(rec.tde_count, 0);
    assert_eq!(rec.state.fac, 0);
}

#[test]
fn threshold_is_strict() {
    // v reaches exactly 1000 at step 10 (no spike), 1100 at step 11 (spike).
    let rec = run(row(&[("cco_bias", 100)]), &[], 11);
    assert_eq!(rec.cco_spikes, vec![11.0 * DT]);
}

/// The CCO fires at step 1 (bias above threshold) and then stays refractory; the TDE's
/// facilitatory weight is 1000 and its trigger weight 3 >> 1.
fn gated(changes: &[(&str, i64)]) -> [i64; N_FIXED_PARAMS] {
    let mut r = row(&[
        ("cco_bias", 2000),
        ("cco_refr", 1000),
        ("fac_weight", 1000),
        ("trg_mantissa", 3),
        ("trg_shift", 1),
    ]);
    for &(name, value) in changes {
        r[FIXED_PARAM_NAMES.iter().position(|n| *n == name).unwrap()] = value;
    }
    r
}

#[test]
fn trigger_gates_with_the_facilitatory_current_of_the_previous_step() {
    // One input during step 1. Step 1: f = 1000, CCO fires. Step 2: g += (1000*3)>>1 = 1500,
    // v_tde = 1500. Step 3: v_tde = 3000 (no decays anywhere).
    let rec = run(gated(&[]), &[0.5 * DT], 3);
    assert_eq!(rec.cco_count, 1);
    assert_eq!(
        (rec.state.fac, rec.state.trg, rec.state.v_tde),
        (1000, 1500, 3000)
    );
    // Without the input the gate is closed.
    let rec = run(gated(&[]), &[], 3);
    assert_eq!((rec.state.trg, rec.state.v_tde), (0, 0));
}

#[test]
fn current_shift_gives_the_membrane_the_integer_part() {
    // g = 1500 with 4 fractional bits: the membrane adds 1500 >> 4 = 93 per step.
    let rec = run(gated(&[("tde_current_shift", 4)]), &[0.5 * DT], 3);
    assert_eq!((rec.state.trg, rec.state.v_tde), (1500, 186));
}

#[test]
fn spikes_are_delivered_one_step_later() {
    // The TDE fires as soon as the trigger current arrives (step 2); its spike reaches the
    // CCO synapse at step 3.
    let r = gated(&[
        ("cco_weight", 77),
        ("trg_shift", 0),
        ("trg_mantissa", 1),
        ("tde_threshold", 10),
        ("tde_refr", 1000),
    ]);
    let at2 = run(r, &[0.5 * DT], 2);
    assert_eq!(at2.tde_spikes, vec![2.0 * DT]);
    assert_eq!(
        at2.state.u_cco, 0,
        "the TDE spike has not reached the CCO yet"
    );
    assert!(at2.state.tde_fired);
    let at3 = run(r, &[0.5 * DT], 3);
    assert_eq!(at3.state.u_cco, 77);
}

#[test]
fn refractory_holds_the_potential_while_currents_evolve() {
    let r = row(&[("cco_syn_decay", 2048), ("cco_bias", 2000), ("cco_refr", 3)]);
    let rec = run(r, &[], 3);
    // Spike at step 1, refractory for steps 2..4.
    assert_eq!(rec.cco_spikes, vec![DT]);
    assert_eq!((rec.state.v_cco, rec.state.cco_refr_left), (0, 1));
    let rec = run(r, &[], 5);
    assert_eq!(rec.cco_spikes, vec![DT, 5.0 * DT]);
}

#[test]
fn saturation_clips_and_counts() {
    let max = format().state_max();
    // One input fills the facilitatory current.
    let rec = run(
        row(&[("fac_weight", max)]),
        &[0.1 * DT, 0.2 * DT, 1.5 * DT],
        2,
    );
    assert_eq!(rec.state.fac, max);
    assert_eq!(rec.saturations, [2, 0, 0, 0, 0]);
}

#[test]
fn inputs_arrive_in_the_step_they_happen_in() {
    let steps = input_steps(&[0.0, 0.5 * DT, DT, 1.5 * DT, 2.0 * DT, 9.0], DT, 0, 3, "x").unwrap();
    assert_eq!(steps, vec![1, 1, 1, 2, 2]);
}

#[test]
fn batch_equals_one_by_one_and_does_not_depend_on_threads() {
    let params = lively_network();
    let trains: Vec<Vec<f64>> = (0..4)
        .map(|s| {
            (0..300)
                .map(|j| (j as f64 * 0.0031 + s as f64 * 1e-4) % 1.0)
                .collect()
        })
        .map(|mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v
        })
        .collect();
    let views: Vec<&[f64]> = trains.iter().map(Vec::as_slice).collect();
    let cfg = config(1.0);
    let batch = simulate_fixed(&params, &format(), &views, cfg, Some(2)).unwrap();
    let serial = simulate_fixed(&params, &format(), &views, cfg, Some(1)).unwrap();
    assert_eq!(batch, serial);
    for (i, v) in views.iter().enumerate() {
        let alone = simulate_fixed(&params, &format(), &[v], cfg, None).unwrap();
        assert_eq!(alone[0], batch[i]);
    }
    assert!(batch[0].iter().all(|r| r.tde_count > 0 && r.cco_count > 0));
}

/// The batch test's network: both neurons of both sPLLs spike, and their currents decay.
fn lively_network() -> Vec<FixedSpll> {
    let base = [
        ("cco_syn_decay", 300),
        ("cco_decay", 5),
        ("cco_weight", 400),
        ("cco_current_shift", 1),
        ("cco_bias", 180),
        ("cco_refr", 10),
        ("cco_threshold", 20_000),
        ("fac_decay", 40),
        ("trg_decay", 200),
        ("tde_decay", 90),
        ("fac_weight", 1 << 17),
        ("trg_mantissa", 107),
        ("trg_shift", 10),
        ("tde_current_shift", 1),
        ("tde_refr", 10),
        ("tde_threshold", 50_000),
    ];
    let mut other = base;
    other[4].1 = 260;
    vec![spll(row(&base)), spll(row(&other))]
}

#[test]
fn runs_over_several_cancel_polls_equal_the_reference() {
    // The step loop stops every CANCEL_POLL steps to poll the cancel flag; with a high CCO
    // threshold a block spikes on fewer steps than fill the spike buffer between two polls,
    // so it stops at the polls.
    let n_steps = 3 * kernel::CANCEL_POLL + 17;
    let params = [FixedSpll {
        cco_threshold: 70_000,
        ..lively_network()[0]
    }];
    let inputs: Vec<f64> = (0..400).map(|j| j as f64 * 0.049).collect();
    let cfg = config(n_steps as f64 * DT);
    let arrivals = input_steps(&inputs, DT, 0, n_steps, "x").unwrap();
    let expected: Vec<FixedRecord> = params
        .iter()
        .map(|p| reference_run(p, &format(), &arrivals, n_steps, DT, true))
        .collect();
    assert!(expected.iter().all(|r| r.tde_count > 0));
    let spikes: u64 = expected.iter().map(|r| r.tde_count + r.cco_count).sum();
    assert!(spikes < 3 * kernel::SPIKE_BUFFER as u64, "{spikes} spikes");
    for kernel in Kernel::available() {
        let got = simulate_with(kernel, &params, &format(), &[&inputs], cfg, Some(1));
        assert_eq!(got.unwrap()[0], expected, "{kernel:?}");
    }
}

#[test]
fn a_raised_cancel_stops_a_run_within_milliseconds() {
    let params = lively_network();
    let cancel = Cancel::new();
    // A billion steps: minutes of work.
    let cfg = StepConfig {
        cancel: &cancel,
        ..config(MAX_STEPS as f64 * DT)
    };
    let start = std::time::Instant::now();
    let result = std::thread::scope(|scope| {
        scope.spawn(|| {
            std::thread::sleep(std::time::Duration::from_millis(50));
            cancel.request();
        });
        simulate_fixed(&params, &format(), &[&[0.1]], cfg, Some(1))
    });
    assert_eq!(result.unwrap_err().0, crate::cancel::CANCELLED);
    assert!(start.elapsed().as_secs_f64() < 1.0, "{:?}", start.elapsed());
    let periods = cco_free_periods(&params, &format(), MAX_STEPS, &cancel);
    assert_eq!(periods.unwrap_err().0, crate::cancel::CANCELLED);
}

#[test]
fn bad_input_is_an_error_naming_the_problem() {
    fn err<T>(r: Result<T, EngineError>) -> String {
        r.map(|_| ()).unwrap_err().0
    }
    let f = format();
    let bad = |name: &str, value: i64| err(FixedSpll::from_row(&row(&[(name, value)]), 3, &f));
    assert!(FixedFormat::new(33, 12)
        .unwrap_err()
        .0
        .contains("state_bits"));
    assert!(FixedFormat::new(24, 0)
        .unwrap_err()
        .0
        .contains("decay_bits"));
    assert!(bad("cco_decay", 4097).contains("sPLL 3: fixed-point parameter cco_decay"));
    assert!(bad("fac_weight", -1).contains("fac_weight"));
    assert!(bad("tde_threshold", f.state_max()).contains("tde_threshold"));
    assert!(bad("trg_shift", 63).contains("trg_shift"));
    assert!(bad("tde_current_shift", 31).contains("tde_current_shift"));
    assert!(bad("cco_refr", -2).contains("cco_refr"));
    assert!(err(FixedSpll::from_row(&row(&[])[..5], 0, &f)).contains("expected 16"));
    assert!(err(FixedSpll::from_matrix(&[], &f)).contains("shape"));
    let p = [spll(row(&[]))];
    let run_with =
        |inputs: &[f64], cfg: StepConfig| err(simulate_fixed(&p, &f, &[inputs], cfg, None));
    assert!(run_with(&[f64::NAN], config(1.0)).contains("not a finite time"));
    assert!(run_with(&[0.2, 0.1], config(1.0)).contains("sorted"));
    assert!(run_with(&[-0.1], config(1.0)).contains("negative"));
    assert!(run_with(&[], config(0.4 * DT)).contains("shorter than half a time step"));
    assert!(run_with(&[], config(f64::INFINITY)).contains("duration"));
    let mut cfg = config(1.0);
    cfg.dt = 0.0;
    assert!(run_with(&[], cfg).contains("dt"));
    cfg.dt = 1e-10;
    assert!(run_with(&[], cfg).contains("more than the limit"));
    assert!(err(simulate_fixed(&p, &f, &[&[]], config(1.0), Some(0))).contains("threads"));
    assert!(err(simulate_fixed(&[], &f, &[&[]], config(1.0), None)).contains("at least one"));
}
/// splitmix64: a small deterministic generator for the random cases below.
fn next(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniform integer in `[low, high]`.
fn between(state: &mut u64, low: i64, high: i64) -> i64 {
    low + (next(state) % (high - low + 1) as u64) as i64
}

/// A random valid row for `format`, drawn to spike, saturate and hit the edge values
/// (decay constants 0, if `zero_decays`, and `2^D`, zero refractory periods, large shifts)
/// often.
fn random_row(state: &mut u64, format: &FixedFormat, zero_decays: bool) -> [i64; N_FIXED_PARAMS] {
    let max = format.state_max();
    let unity = format.decay_unity();
    let mut r = [0; N_FIXED_PARAMS];
    for (value, name) in r.iter_mut().zip(FIXED_PARAM_NAMES) {
        let scale = between(state, 0, 8) as u32;
        *value = match name {
            "cco_syn_decay" | "cco_decay" | "fac_decay" | "trg_decay" | "tde_decay" => {
                match between(state, 0, 9) {
                    0 if zero_decays => 0,
                    1 => unity,
                    _ => (between(state, 0, unity) >> scale.min(format.decay_bits)).max(1),
                }
            }
            "cco_weight" | "cco_bias" | "fac_weight" => between(state, 0, max) >> scale,
            "cco_threshold" | "tde_threshold" => between(state, 0, max - 1) >> scale,
            "trg_mantissa" => between(state, 0, i64::from(i32::MAX)) >> (4 * scale),
            "trg_shift" => between(state, 0, MAX_TRIGGER_SHIFT) >> (scale / 2),
            "cco_current_shift" | "tde_current_shift" => {
                between(state, 0, i64::from(MAX_CURRENT_SHIFT)) >> (scale / 2)
            }
            _ => between(state, 0, 12),
        };
    }
    r
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

    /// Every step-loop implementation this CPU can run (the scalar fallback, AVX-512, AVX-512
    /// with IFMA decays, which only blocks without zero decay constants use) equals the
    /// plain scalar reference on random networks (with or without facilitatory constants
    /// shared by every sPLL, which step as one scalar), formats and inputs, one sample over
    /// sPLLs and a batch over samples.
    #[test]
    fn kernels_equal_the_plain_reference(
        state_bits in 2u32..=MAX_STATE_BITS,
        decay_bits in 1u32..=MAX_DECAY_BITS,
        n_spll in 1usize..=19,
        n_steps in 1u64..=400,
        zero_decays: bool,
        shared_fac: bool,
        seed: u64,
    ) {
        let format = FixedFormat::new(state_bits, decay_bits).unwrap();
        let mut rng = seed;
        let mut rows: Vec<_> =
            (0..n_spll).map(|_| random_row(&mut rng, &format, zero_decays)).collect();
        if shared_fac {
            // Every sPLL with the same facilitatory constants, as in most networks.
            let column = |name| FIXED_PARAM_NAMES.iter().position(|n| *n == name).unwrap();
            for name in ["fac_decay", "fac_weight"] {
                let k = column(name);
                let first = rows[0][k];
                rows.iter_mut().for_each(|r| r[k] = first);
            }
        }
        let params: Vec<FixedSpll> = rows
            .iter()
            .enumerate()
            .map(|(i, row)| FixedSpll::from_row(row, i, &format).unwrap())
            .collect();
        let trains: Vec<Vec<f64>> = (0..2)
            .map(|_| {
                let n = between(&mut rng, 0, 3 * n_steps as i64);
                // Few distinct times, so many spikes share a step.
                let spread = between(&mut rng, 1, n_steps as i64);
                let mut t: Vec<f64> =
                    (0..n).map(|_| between(&mut rng, 0, spread) as f64 * DT * 0.999).collect();
                t.sort_by(f64::total_cmp);
                t
            })
            .collect();
        let views: Vec<&[f64]> = trains.iter().map(Vec::as_slice).collect();
        let cfg = config(n_steps as f64 * DT);
        let expected: Vec<Vec<FixedRecord>> = views
            .iter()
            .map(|x| {
                let arrivals = input_steps(x, DT, 0, n_steps, "x").unwrap();
                params
                    .iter()
                    .map(|p| reference_run(p, &format, &arrivals, n_steps, DT, true))
                    .collect()
            })
            .collect();
        for kernel in Kernel::available() {
            let batch =
                simulate_with(kernel, &params, &format, &views, cfg, Some(2)).unwrap();
            proptest::prop_assert_eq!(&batch, &expected, "{:?}, batch", kernel);
            let one = simulate_with(kernel, &params, &format, &views[..1], cfg, Some(2));
            proptest::prop_assert_eq!(&one.unwrap()[0], &expected[0], "{:?}, one", kernel);
            let pieces = resumed_in_pieces(kernel, &params, &format, &views, n_steps, seed);
            proptest::prop_assert_eq!(&pieces, &expected, "{:?}, resumed", kernel);
        }
    }
}

/// The run of `inputs` for `n_steps` steps made of up to four pieces, each resumed from the
/// last one's final states, with their spikes and saturations joined.
fn resumed_in_pieces(
    kernel: Kernel,
    params: &[FixedSpll],
    format: &FixedFormat,
    inputs: &[&[f64]],
    n_steps: u64,
    seed: u64,
) -> Vec<Vec<FixedRecord>> {
    let mut rng = seed ^ 0x5eed;
    let mut ends: Vec<u64> = (0..3)
        .map(|_| between(&mut rng, 1, n_steps as i64) as u64)
        .collect();
    ends.push(n_steps);
    ends.sort_unstable();
    ends.dedup();
    let mut joined: Vec<Vec<FixedRecord>> =
        vec![vec![FixedRecord::default(); params.len()]; inputs.len()];
    let mut starts: Vec<Vec<FixedState>> = Vec::new();
    let mut begin = 0;
    for end in ends {
        let arrives = |t: &f64| ((t / DT).ceil() as u64).max(1) > begin;
        let pieces: Vec<Vec<f64>> = inputs
            .iter()
            .map(|x| x.iter().copied().filter(arrives).collect())
            .collect();
        let views: Vec<&[f64]> = pieces.iter().map(Vec::as_slice).collect();
        let cfg = StepConfig {
            start_step: begin,
            starts: &starts,
            ..config(end as f64 * DT)
        };
        let out = simulate_with(kernel, params, format, &views, cfg, Some(2)).unwrap();
        for (whole, piece) in joined.iter_mut().zip(&out) {
            for (w, p) in whole.iter_mut().zip(piece) {
                w.tde_spikes.extend(&p.tde_spikes);
                w.cco_spikes.extend(&p.cco_spikes);
                w.tde_count += p.tde_count;
                w.cco_count += p.cco_count;
                w.saturations
                    .iter_mut()
                    .zip(p.saturations)
                    .for_each(|(a, b)| *a += b);
                w.state = p.state;
            }
        }
        starts = out
            .iter()
            .map(|s| s.iter().map(|r| r.state).collect())
            .collect();
        begin = end;
    }
    joined
}
#[test]
fn free_periods_are_the_first_spike_of_an_empty_run_plus_the_refractory_period() {
    let mut rng = 7;
    for case in 0..300 {
        let state_bits = between(&mut rng, 2, i64::from(MAX_STATE_BITS)) as u32;
        let decay_bits = between(&mut rng, 1, i64::from(MAX_DECAY_BITS)) as u32;
        let format = FixedFormat::new(state_bits, decay_bits).unwrap();
        let p = FixedSpll::from_row(&random_row(&mut rng, &format, true), 0, &format).unwrap();
        let max_steps = between(&mut rng, 1, 3000) as u64;
        let empty = reference_run(&p, &format, &[], max_steps, DT, true);
        let expected = empty
            .cco_spikes
            .first()
            .map_or(0, |t| (t / DT).round() as u64 + p.cco_refr as u64);
        let got = cco_free_periods(&[p], &format, max_steps, &NEVER).unwrap();
        assert_eq!(got, vec![expected], "case {case}: {p:?}, {max_steps} steps");
    }
    // A CCO whose potential settles below its threshold never fires.
    let p = spll(row(&[("cco_decay", 2048), ("cco_bias", 400)]));
    assert_eq!(
        cco_free_periods(&[p], &format(), MAX_STEPS, &NEVER).unwrap(),
        vec![0]
    );
    let r = row(&[("cco_bias", 70), ("cco_refr", 9), ("cco_threshold", 1000)]);
    assert_eq!(
        cco_free_periods(&[spll(r)], &format(), 100, &NEVER).unwrap(),
        vec![1000 / 70 + 1 + 9]
    );
    assert_eq!(
        cco_free_periods(&[spll(r)], &format(), 14, &NEVER).unwrap(),
        vec![0]
    );
    assert!(
        cco_free_periods(&[spll(r)], &format(), MAX_STEPS + 1, &NEVER)
            .unwrap_err()
            .0
            .contains("max_steps")
    );
}

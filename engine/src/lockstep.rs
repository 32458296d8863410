//! Independent sPLL runs stepped in lockstep, [`LANES`] at a time, so that the commonest event
//! of all of them is computed by one stream of vector instructions.
//!
//! An event of one sPLL is a short chain of exponentials, divisions and branches; run one
//! after the other, the processor spends most of its time waiting on that chain. Most events
//! are the same kind: the CCO fires alone, the facilitatory current gates the trigger, the TDE
//! advances and either stays below threshold or crosses it within a few root samples, and the
//! CCO's next spike from reset is found with one Halley step (98 % of the CCO spikes of
//! `benchmarks/bench_engine.py`). `fast_cco_event` computes that path for every lane at
//! once with selects in place of branches, on [`Lanes`], whose operations compile to AVX-512
//! code (`fast_round`). A lane whose event is of any other kind (a TDE spike, a probe, a
//! gate, the end), or leaves the path midway, keeps its state and takes the ordinary
//! [`Stepper::step`] instead. Without AVX-512 every event does ([`run_group`]).
//!
//! Both paths call the same functions of [`Neuron`], written once for any [`Real`], with the
//! engine's own elementary functions ([`crate::lanes`]), so a run gets the same bits in a lane,
//! alone, or on a processor without AVX-512 (`tests::lockstep_equals_one_run_at_a_time`).

use crate::error::EngineError;
use crate::lanes::{Lanes, Mask, Real, LANES};
use crate::membrane::Neuron;
use crate::spll::{decayed, run_interleaved, NeuronState, Stepper, CANCEL_POLL};

/// Most samples the fast path spends on a TDE's crossing before handing the event back.
const ROOT_SAMPLES: usize = 8;

/// A neuron's state, in any [`Real`] (one per lane for [`Lanes`]).
#[derive(Clone, Copy, Debug)]
struct State<T> {
    t0: T,
    v0: T,
    i0: T,
    refr_end: T,
    next_spike: T,
}

/// What the fast path needs of the state at the event.
#[derive(Clone, Copy, Debug)]
struct EventIn<T> {
    /// Time of the event: the CCO's planned spike [s].
    t: T,
    tde: State<T>,
    cco_t0: T,
    cco_i0: T,
    /// Facilitatory current [A] at `fac_t` [s], its last input before `t`.
    fac_i: T,
    fac_t: T,
    inv_tau_fac: T,
    g_trg: T,
}

/// The fast path's result: both neurons' new states, and whether the event stayed on the
/// path (`ok`; otherwise nothing of it is used).
#[derive(Clone, Copy, Debug)]
struct EventOut<T: Real> {
    tde: State<T>,
    cco: State<T>,
    ok: T::Mask,
}

/// A CCO spike at `x.t` with no TDE spike, as [`Stepper::step`] computes it, without branches:
/// the CCO fires, the trigger `g_trg I_fac` is added to the advanced TDE, and both neurons are
/// re-planned. `ok` is false where `step` would leave this path: no trigger, a TDE that might
/// reach threshold, or a CCO whose crossing needs more than the first Halley step.
#[inline(always)]
fn fast_cco_event<T: Real>(tde: &Neuron<T>, cco: &Neuron<T>, x: &EventIn<T>) -> EventOut<T> {
    let (zero, inf) = (T::splat(0.0), T::splat(f64::INFINITY));
    let t = x.t;
    // The CCO fires (NeuronState::fire).
    let i_cco = cco.current(x.cco_i0, t - x.cco_t0);
    // Facilitatory current just before t (Facilitation::current), and the trigger it gates.
    let i_fac = decayed(x.fac_i, x.fac_t, t, x.inv_tau_fac);
    let trigger = x.g_trg * i_fac;
    // The TDE advances to t (NeuronState::at, its four cases) and receives the trigger.
    let s = x.tde;
    let at_t0 = t.eq(s.t0);
    let refractory = t.le(s.refr_end);
    let was_refractory = s.t0.lt(s.refr_end);
    let decay_time = T::select(refractory, t - s.t0, s.refr_end - s.t0);
    let i_decayed = tde.current(s.i0, decay_time);
    let free_time = T::select(was_refractory, t - s.refr_end, t - s.t0);
    let v_free = T::select(was_refractory, zero, s.v0);
    let i_free = T::select(was_refractory, i_decayed, s.i0);
    let (v_evolved, i_evolved) = tde.evolve(v_free, i_free, free_time);
    let v_tde = T::select(
        at_t0,
        T::select(t.lt(s.refr_end), zero, s.v0),
        T::select(refractory, zero, v_evolved),
    );
    let i_tde = T::select(at_t0, s.i0, T::select(refractory, i_decayed, i_evolved)) + trigger;
    // The TDE is re-planned (NeuronState::plan from t0 = t).
    let free_from = t.max(s.refr_end);
    let just_fired = (t + tde.t_refr).eq(s.refr_end) & t.lt(s.refr_end);
    let i_after_refr = tde.current(i_tde, s.refr_end - t);
    let from_now = free_from.eq(t);
    let v_plan = T::select(just_fired, zero, T::select(from_now, v_tde, zero));
    let i_plan = T::select(
        just_fired,
        i_tde * tde.refr_syn_decay,
        T::select(from_now, i_tde, i_after_refr),
    );
    // NeuronState::time_to_threshold for a neuron that does not rise to threshold: firing at
    // once, quiet (a cheap bound, no interior extremum, a peak clearly or surely below
    // threshold), or a crossing before the extremum, found by the root solver.
    let start = tde.start_sample(v_plan, i_plan);
    let fires_now = zero.le(start.f);
    let (s_ext, has_extremum) = tde.extremum_time(v_plan, i_plan);
    let ext = tde.sample(v_plan, i_plan, s_ext);
    let may_fire = !tde.rises_to_threshold()
        & !fires_now
        & !tde.stays_below(v_plan, i_plan, &start)
        & has_extremum
        & !tde.peak_below(i_plan, s_ext);
    let crossing = may_fire & zero.le(ext.f);
    let (s_cross, found) = tde.root_in_bracket(
        (v_plan, i_plan),
        (zero, &start),
        s_ext,
        crossing,
        ROOT_SAMPLES,
    );
    let tde_next = T::select(
        fires_now,
        free_from + zero,
        T::select(crossing, free_from + s_cross, inf),
    );
    let tde_ok = fires_now | (!tde.rises_to_threshold() & (!crossing | found));
    // The CCO is re-planned from reset (V = 0 at the end of its refractory period).
    let cco_refr_end = t + cco.t_refr;
    let cco_free = t.max(cco_refr_end);
    let cco_just_fired = (t + cco.t_refr).eq(cco_refr_end) & t.lt(cco_refr_end);
    let i0 = T::select(cco_just_fired, i_cco * cco.refr_syn_decay, i_cco);
    let cco_start = cco.start_sample(zero, i0);
    let cco_fires_now = zero.le(cco_start.f);
    let charges = cco.rises_to_threshold() & zero.le(i0);
    let silent = i0.eq(zero);
    let guess = cco.guess_from_reset(i0);
    let hi = cco.charge_time();
    let in_bracket = zero.lt(guess) & guess.lt(hi);
    let here = cco.sample(zero, i0, guess);
    let update = cco.root_update(guess, &here, zero, hi);
    let crossing = T::select(cco_fires_now, zero, T::select(silent, hi, update.answer));
    let cco_ok = cco_fires_now | (charges & (silent | (in_bracket & update.done)));
    EventOut {
        tde: State {
            t0: t,
            v0: v_tde,
            i0: i_tde,
            refr_end: s.refr_end,
            next_spike: tde_next,
        },
        cco: State {
            t0: t,
            v0: zero,
            i0: i_cco,
            refr_end: cco_refr_end,
            next_spike: cco_free + crossing,
        },
        ok: !trigger.eq(zero) & tde_ok & cco_ok,
    }
}

/// The lanes' neurons and their events, one field per [`Lanes`]. A lane that is empty or off
/// the fast path this round keeps its last values, zeros at first (computed on and ignored:
/// plain arithmetic on any numbers cannot fault).
struct Block {
    neurons: [(Neuron, Neuron); LANES],
    tde: Neuron<Lanes>,
    cco: Neuron<Lanes>,
    input: EventIn<Lanes>,
    output: EventOut<Lanes>,
}

impl Block {
    fn new(tde: Neuron, cco: Neuron) -> Self {
        let zeros = Lanes::splat(0.0);
        let state = State {
            t0: zeros,
            v0: zeros,
            i0: zeros,
            refr_end: zeros,
            next_spike: zeros,
        };
        Block {
            neurons: [(tde, cco); LANES],
            tde: Neuron::gather(&[tde; LANES]),
            cco: Neuron::gather(&[cco; LANES]),
            input: EventIn {
                t: zeros,
                tde: state,
                cco_t0: zeros,
                cco_i0: zeros,
                fac_i: zeros,
                fac_t: zeros,
                inv_tau_fac: zeros,
                g_trg: zeros,
            },
            output: EventOut {
                tde: state,
                cco: state,
                ok: Mask([false; LANES]),
            },
        }
    }

    /// Put a run's neurons into lane `l` ([`regather`](Self::regather) before the next round).
    fn load(&mut self, l: usize, tde: Neuron, cco: Neuron) {
        self.neurons[l] = (tde, cco);
    }

    /// Rebuild the lane-wise neurons after [`load`](Self::load)s.
    fn regather(&mut self) {
        self.tde = Neuron::gather(&core::array::from_fn(|l| self.neurons[l].0));
        self.cco = Neuron::gather(&core::array::from_fn(|l| self.neurons[l].1));
    }
}

/// [`fast_cco_event`] on every lane.
#[inline(always)]
fn round_all_lanes(block: &mut Block) {
    block.output = fast_cco_event(&block.tde, &block.cco, &block.input);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx2,fma")]
unsafe fn fast_round_avx512(block: &mut Block) {
    round_all_lanes(block)
}

/// The vector round, if this processor has AVX-512. Narrower vectors do not pay: on this
/// workload the lockstep engine took 1.3x (AVX2) and 1.8x (SSE2) the time of the previous
/// event-by-event engine, against 0.85x with AVX-512. Every variant gives the same bits (Rust
/// never fuses a multiply and an add on its own), so the choice changes only the speed.
fn fast_round() -> Option<fn(&mut Block)> {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512dq")
            && std::is_x86_feature_detected!("avx512vl")
        {
            // SAFETY: the features it is compiled for are present.
            return Some(|block| unsafe { fast_round_avx512(block) });
        }
    }
    None
}

/// Put `run`'s next event into lane `l` of the block and say so, or say that the event is of
/// another kind (a TDE spike, the end, a probe to sample first, a gate, the event limit or a
/// cancel poll due). Moves the run's gate cursor to the event (as `step` would).
fn fast_input(run: &mut Stepper<'_>, block: &mut Block, l: usize) -> bool {
    let (tde, cco) = (&run.state.tde, &run.state.cco);
    let t = cco.next_spike;
    let probe_first = run.probes.get(run.next_probe).is_some_and(|&p| p < t);
    let events = run.events + 1;
    if !(t < tde.next_spike && t <= run.t_end)
        || probe_first
        || run.gate.is_some()
        || events > run.config.max_events
        || events.is_multiple_of(CANCEL_POLL)
    {
        return false;
    }
    run.fac.seek(&mut run.gate_cursor, t, false);
    let (fac_i, fac_t) = run.fac.last_input(run.gate_cursor);
    let x = &mut block.input;
    x.t.0[l] = t;
    x.tde.t0.0[l] = tde.t0;
    x.tde.v0.0[l] = tde.v0;
    x.tde.i0.0[l] = tde.i0;
    x.tde.refr_end.0[l] = tde.refr_end;
    x.cco_t0.0[l] = cco.t0;
    x.cco_i0.0[l] = cco.i0;
    x.fac_i.0[l] = fac_i;
    x.fac_t.0[l] = fac_t;
    x.inv_tau_fac.0[l] = run.p.inv_tau_fac;
    x.g_trg.0[l] = run.p.g_trg;
    true
}

/// Take the fast path's result in lane `l` for `run`: the states, the count and the spike.
fn commit(run: &mut Stepper<'_>, block: &Block, l: usize) {
    let lane = |s: &State<Lanes>| NeuronState {
        t0: s.t0.0[l],
        v0: s.v0.0[l],
        i0: s.i0.0[l],
        refr_end: s.refr_end.0[l],
        next_spike: s.next_spike.0[l],
    };
    run.state.tde = lane(&block.output.tde);
    run.state.cco = lane(&block.output.cco);
    run.events += 1;
    run.rec.cco_count += 1;
    if run.rec.keep_spikes {
        run.rec.cco_spikes.push(block.input.t.0[l]);
    }
}

/// Run independent sPLL runs to their ends: [`LANES`] at a time in lockstep on a processor with
/// AVX-512, elsewhere (or when every run is gated) two at a time with their events interleaved
/// ([`run_interleaved`]). The
/// results are those of running them one after the other, bit for bit, either way. An error
/// names the run (its position in `runs`).
pub fn run_group(runs: Vec<Stepper<'_>>) -> Result<(), (usize, EngineError)> {
    // Gated runs (the standard-neuron sPLL) never take the fast path.
    let round = fast_round().filter(|_| runs.iter().any(|run| run.gate.is_none()));
    match round {
        Some(round) => run_lockstep(runs, round),
        None => {
            let mut runs = runs.into_iter().enumerate();
            while let Some(first) = runs.next() {
                run_interleaved([Some(first), runs.next()].into_iter().flatten().collect())?;
            }
            Ok(())
        }
    }
}

/// [`run_group`] in lockstep, refilling a lane from `runs` as its run ends, with `round` the
/// vector round.
fn run_lockstep(runs: Vec<Stepper<'_>>, round: fn(&mut Block)) -> Result<(), (usize, EngineError)> {
    let Some(first) = runs.first() else {
        return Ok(());
    };
    let mut block = Block::new(first.p.tde, first.p.cco);
    let mut waiting = runs.into_iter().enumerate();
    let mut slots: Vec<Option<(usize, Stepper<'_>)>> = (0..LANES).map(|_| None).collect();
    let mut fast = [false; LANES];
    loop {
        let mut any = false;
        let mut refilled = false;
        for (l, slot) in slots.iter_mut().enumerate() {
            if slot.is_none() {
                if let Some((index, run)) = waiting.next() {
                    block.load(l, run.p.tde, run.p.cco);
                    refilled = true;
                    *slot = Some((index, run));
                }
            }
            fast[l] = match slot {
                Some((_, run)) => {
                    any = true;
                    fast_input(run, &mut block, l)
                }
                None => false,
            };
        }
        if !any {
            return Ok(());
        }
        if refilled {
            block.regather();
        }
        // No lane on the fast path (say, every run gated): the round would be wasted.
        if fast.contains(&true) {
            round(&mut block);
        }
        for (l, slot) in slots.iter_mut().enumerate() {
            let Some((index, run)) = slot else { continue };
            if fast[l] && block.output.ok.0[l] {
                commit(run, &block, l);
                continue;
            }
            match run.step() {
                Ok(true) => {}
                Ok(false) => slot.take().expect("the slot holds a run").1.finish(),
                Err(e) => return Err((*index, e)),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::cancel::NEVER;
    use crate::network::tests::{bursts, periodic};
    use crate::network::{simulate, RunConfig};
    use crate::params::SpllParams;
    use crate::spll::{run, run_interleaved, Facilitation, Recorder, SpllState, Stepper};
    use proptest::prelude::*;

    /// A parameter row around the thesis's Table 6 values, each time constant, gain and
    /// threshold scaled by `10^u` for its `u` in `spread`, refractory periods possibly 0, and
    /// the CCO's offset set for a free frequency `f` [Hz] (or below threshold for `f = 0`).
    fn row(spread: &[f64; 11], f: f64, no_refractory: bool) -> Vec<f64> {
        let scale = |k: usize, x: f64| x * 10f64.powf(spread[k]);
        let t_refr = if no_refractory { 0.0 } else { 1e-3 };
        let (tau_cco, c_cco, v_cco) = (scale(0, 0.314), 1.0, scale(1, 1.0));
        let offset = if f > 0.0 {
            v_cco * c_cco / (tau_cco * -(-(1.0 / f - t_refr) / tau_cco).exp_m1())
        } else {
            0.5 * v_cco * c_cco / tau_cco
        };
        vec![
            scale(2, 7.5e-3),
            tau_cco,
            c_cco,
            scale(3, 9.84),
            offset,
            t_refr,
            v_cco,
            scale(4, 9.59e-3),
            scale(5, 1.25e-3),
            scale(6, 4.52e-3),
            1.0,
            scale(7, 615.0),
            scale(8, 0.271),
            if no_refractory { 0.0 } else { scale(9, 1e-3) },
            scale(10, 1.0),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// A network of varied sPLLs run in lockstep (with probes, kept spikes and more sPLLs
        /// than lanes, so lanes are refilled), and the same sPLLs run interleaved, give every
        /// sPLL the spikes, traces and final state, bit for bit, of its plain event-by-event
        /// run alone.
        #[test]
        fn lockstep_equals_one_run_at_a_time(
            spreads in proptest::collection::vec(proptest::array::uniform11(-0.5f64..0.5), 21),
            frequencies in proptest::collection::vec(0.0f64..700.0, 21),
            rate in 50.0f64..600.0,
            bursty: bool,
        ) {
            let params: Vec<SpllParams> = spreads
                .iter()
                .zip(&frequencies)
                .enumerate()
                .map(|(i, (spread, &f))| {
                    let f = if i % 7 == 3 { 0.0 } else { f.max(20.0) };
                    SpllParams::from_row(&row(spread, f, i % 5 == 4), i).unwrap()
                })
                .collect();
            let t_end = 0.6;
            let inputs = if bursty { bursts(rate, t_end) } else { periodic(rate, t_end) };
            let probes = [0.05, 0.3, 0.3, 0.59];
            let config = RunConfig {
                keep_spikes: true,
                // Parameters that make a neuron fire absurdly fast are skipped, not simulated.
                max_events: 200_000,
                cancel: &NEVER,
                gate: None,
            };
            let all = simulate(&params, &inputs, t_end, None, &probes, config, false);
            prop_assume!(all.is_ok());
            let all = all.unwrap();
            let mut spikes = 0;
            for (i, p) in params.iter().enumerate() {
                let mut state = SpllState::new(p);
                let mut alone = Recorder { keep_spikes: true, ..Recorder::default() };
                run(p, &mut state, &inputs, t_end, &probes, &config, &mut alone).unwrap();
                let lanes = &all.recorders[i];
                prop_assert_eq!(&lanes.tde_spikes, &alone.tde_spikes, "sPLL {}", i);
                prop_assert_eq!(&lanes.cco_spikes, &alone.cco_spikes, "sPLL {}", i);
                prop_assert_eq!(&lanes.trace, &alone.trace, "sPLL {}", i);
                prop_assert_eq!(all.states[i], state, "sPLL {}", i);
                spikes += alone.tde_count;
            }
            // A draw without TDE spikes checks little of the path (its CCO spikes still agree).
            prop_assume!(spikes > 0);
            // The interleaved driver (processors without AVX-512) gives the same.
            let mut states: Vec<SpllState> = params.iter().map(SpllState::new).collect();
            let mut recs: Vec<Recorder> =
                params.iter().map(|_| Recorder { keep_spikes: true, ..Recorder::default() }).collect();
            let facs: Vec<Facilitation> = params
                .iter()
                .zip(&states)
                .map(|(p, s)| Facilitation::new(p, s, &inputs, t_end))
                .collect();
            let runs = params
                .iter()
                .zip(states.iter_mut())
                .zip(recs.iter_mut())
                .zip(&facs)
                .map(|(((p, s), r), f)| Stepper::new(p, s, f, t_end, &probes, &config, r).unwrap())
                .enumerate()
                .collect();
            run_interleaved(runs).unwrap();
            for (i, rec) in recs.iter().enumerate() {
                prop_assert_eq!(&rec.tde_spikes, &all.recorders[i].tde_spikes, "sPLL {}", i);
                prop_assert_eq!(&rec.cco_spikes, &all.recorders[i].cco_spikes, "sPLL {}", i);
                prop_assert_eq!(&rec.trace, &all.recorders[i].trace, "sPLL {}", i);
                prop_assert_eq!(states[i], all.states[i], "sPLL {}", i);
            }
        }
    }
}

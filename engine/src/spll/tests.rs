//! Unit tests of the event-driven sPLL: input seeking, saved states and the event limit.

use super::*;
use crate::cancel::NEVER;
use crate::network::tests::{bursts, periodic, vibtac};

/// Run `p` from rest on `inputs` up to `t_end`, keeping no spikes, with at most `max_events`
/// events: the state it ends in, and the run's result.
fn run_from_rest(
    p: &SpllParams,
    inputs: &[f64],
    t_end: f64,
    max_events: u64,
) -> (SpllState, Result<(), EngineError>) {
    let config = RunConfig {
        keep_spikes: false,
        max_events,
        cancel: &NEVER,
        gate: None,
    };
    let mut state = SpllState::new(p);
    let mut rec = Recorder::default();
    let result = run(p, &mut state, inputs, t_end, &[], &config, &mut rec);
    (state, result)
}

/// The state of `p` after `duration` seconds of bursts of input at 310 Hz, as saved.
fn saved_state(p: &SpllParams, duration: f64) -> [f64; STATE_LEN] {
    let (state, result) = run_from_rest(p, &bursts(310.0, duration), duration, MAX_EVENTS);
    result.unwrap();
    state.to_array()
}

fn check(p: &SpllParams, values: &[f64]) -> Result<(), EngineError> {
    SpllState::from_array(values, 7)?.check(p, 7)
}

#[test]
fn seeking_the_inputs_agrees_with_a_partition_point() {
    let p = vibtac(200.0);
    let inputs = bursts(310.0, 0.5);
    let fac = Facilitation::new(&p, &SpllState::new(&p), &inputs, 0.5);
    let times = &fac.times;
    assert!(times.len() > 20);
    // From every start, to every input time, between input times and past the end.
    let mut targets: Vec<f64> = times.clone();
    targets.extend(times.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    targets.extend([-1.0, 0.0, 1.0]);
    for inclusive in [false, true] {
        for &t in &targets {
            let expected = times.partition_point(|&x| x < t || (inclusive && x == t));
            for start in (0..=expected).step_by(3) {
                let mut k = start;
                fac.seek(&mut k, t, inclusive);
                assert_eq!(k, expected, "t {t}, inclusive {inclusive}, from {start}");
            }
        }
    }
}

#[test]
fn saved_states_pass_their_check_at_any_time() {
    let p = vibtac(200.0);
    for duration in [1e-4, 0.0123, 0.5, 3.0] {
        check(&p, &saved_state(&p, duration)).unwrap();
    }
    check(&p, &SpllState::new(&p).to_array()).unwrap();
}

#[test]
fn a_tampered_state_is_refused_naming_the_value_and_the_spll() {
    let p = vibtac(200.0);
    let good = saved_state(&p, 0.5);
    let field = |name: &str| STATE_NAMES.iter().position(|n| *n == name).unwrap();
    // Both neurons have fired (so every value is in use).
    assert!(good[field("tde_refr_end")].is_finite() && good[field("cco_refr_end")].is_finite());
    let cases = [
        ("t", f64::NAN),
        ("t", -1.0),
        ("fac_i", f64::INFINITY),
        ("fac_i", -3.0),
        ("fac_t", 0.7),
        ("tde_t0", -1.0),
        ("tde_v0", f64::NAN),
        ("tde_v0", 2.0),
        ("tde_i0", 1e300),
        ("cco_refr_end", f64::INFINITY),
        ("cco_refr_end", good[field("cco_t0")] + 0.5),
        ("tde_next_spike", -1.0),
        ("tde_next_spike", f64::NAN),
        ("cco_next_spike", good[field("cco_next_spike")] + 1e-3),
        ("cco_next_spike", f64::INFINITY),
    ];
    for (name, value) in cases {
        let mut tampered = good;
        tampered[field(name)] = value;
        let message = check(&p, &tampered).unwrap_err().0;
        assert!(
            message.starts_with(&format!("saved state of sPLL 7: {name} = ")),
            "{name} = {value}: {message}"
        );
    }
}

#[test]
fn a_consistent_state_that_would_fire_before_its_time_is_refused() {
    // A potential just below threshold plans a spike right after t0, before the state's
    // time.
    let p = vibtac(200.0);
    let mut state = SpllState::from_array(&saved_state(&p, 0.5), 0).unwrap();
    assert!(state.cco.t0 < state.t);
    state.cco.v0 = p.cco.v_thr * (1.0 - 1e-12);
    state.cco.refr_end = f64::NEG_INFINITY;
    state.cco.plan(&p.cco);
    let message = state.check(&p, 0).unwrap_err().0;
    assert!(
        message.contains("cco_next_spike") && message.contains("after the state's time"),
        "{message}"
    );
}

#[test]
fn the_event_limit_says_whether_the_run_is_long_or_the_parameters_run_away() {
    let run_to = |p: &SpllParams, t_end: f64, max_events: u64| {
        let (_, result) = run_from_rest(p, &periodic(300.0, t_end), t_end, max_events);
        result.unwrap_err().0
    };
    let long = run_to(&vibtac(200.0), 100.0, 1000);
    assert!(long.contains("the run is long"), "{long}");
    assert!(long.contains("needs about"), "{long}");
    // No refractory periods, huge gains: the CCO fires without end.
    let fast = [
        1.0, 1.0, 1.0, 1.0, 2000.0, 0.0, 1.0, 10.0, 10.0, 10.0, 1.0, 1e6, 1e6, 0.0, 1.0,
    ];
    let runaway = run_to(&SpllParams::from_row(&fast, 0).unwrap(), 0.01, 100_000);
    assert!(
        runaway.contains("faster than the simulation can resolve"),
        "{runaway}"
    );
    assert!(
        runaway.contains("raise t_tde_refr or t_cco_refr"),
        "{runaway}"
    );
}

//! A NIR graph of standard nodes stepped as clocked consumers step it (`mappings.nir.executor`,
//! whose docstring states the rules): the input's value at each step; a node's input the sum
//! of its incoming edges, in the graph's edge order, an edge that closes a cycle delivering
//! the previous step's value; `Affine` `W x + b` (sparse `W`, each row's terms summed in
//! column order, the terms of zero inputs, which add nothing, skipped);
//! `LIF` `v <- v + a (v_leak - v + r x)`; `CubaLIF` `I <- I + a_syn (w_in x - I)`, then the
//! `LIF` update driven by `I`; a neuron spikes (1.0) when `v > v_threshold` and is set to
//! `v_reset`. Every sum and product is the one numpy makes, in its order, so the results are
//! equal to the bit. Samples are independent; each keeps its own state between calls.

use rayon::prelude::*;

use crate::cancel::Cancel;
use crate::error::{bail, EngineError};

/// Steps between two polls of the cancel flag.
const POLL_STEPS: usize = 1024;

/// A neuron's coefficients, one entry per neuron: `a = dt / tau` and the rest as NIR names them.
#[derive(Clone, Debug)]
pub struct Lif {
    pub a: Vec<f64>,
    pub r: Vec<f64>,
    pub leak: Vec<f64>,
    pub threshold: Vec<f64>,
    pub reset: Vec<f64>,
}

/// What a node computes.
#[derive(Clone, Debug)]
pub enum Kind {
    Input,
    Output,
    /// `W x (+ b)`, `W` of `n_rows` rows by column (CSC): column `j`'s rows
    /// `rows[starts[j]..starts[j + 1]]`, ascending.
    Affine {
        starts: Vec<usize>,
        rows: Vec<usize>,
        data: Vec<f64>,
        n_rows: usize,
        bias: Option<Vec<f64>>,
    },
    Lif(Lif),
    CubaLif {
        a_syn: Vec<f64>,
        w_in: Vec<f64>,
        lif: Lif,
    },
}

/// A node in execution order: its input size, its output size and its sources (index in the
/// order, whether the edge delivers the previous step's value).
#[derive(Clone, Debug)]
pub struct Node {
    pub kind: Kind,
    pub size_in: usize,
    pub preds: Vec<(usize, bool)>,
}

impl Node {
    /// The node's output size.
    pub fn size_out(&self) -> usize {
        match &self.kind {
            Kind::Input | Kind::Output => self.size_in,
            Kind::Affine { n_rows, .. } => *n_rows,
            Kind::Lif(lif) | Kind::CubaLif { lif, .. } => lif.threshold.len(),
        }
    }

    fn is_neuron(&self) -> bool {
        matches!(self.kind, Kind::Lif(_) | Kind::CubaLif { .. })
    }
}

/// The graph in execution order, its input node first.
#[derive(Clone, Debug)]
pub struct NirGraph {
    pub nodes: Vec<Node>,
    pub output: usize,
    /// The nodes whose value an edge delivers a step late (kept from one step to the next).
    carried: Vec<usize>,
}

impl NirGraph {
    /// A graph whose sizes agree, or an error naming the node (by its position in the order)
    /// that does not.
    pub fn new(nodes: Vec<Node>, output: usize) -> Result<Self, EngineError> {
        if !matches!(nodes.first().map(|n| &n.kind), Some(Kind::Input)) {
            bail!("the first node in the order must be the graph's input");
        }
        if output >= nodes.len() {
            bail!(
                "output node {output} is not among the {} nodes",
                nodes.len()
            );
        }
        for (k, node) in nodes.iter().enumerate() {
            let size = node.size_out();
            let check = |what: &str, len: usize| -> Result<(), EngineError> {
                if len != size {
                    bail!("node {k}: {what} has {len} entries, the node {size} outputs");
                }
                Ok(())
            };
            match &node.kind {
                Kind::Input | Kind::Output => {}
                Kind::Affine {
                    starts,
                    rows,
                    data,
                    n_rows,
                    bias,
                } => {
                    let nnz = rows.len();
                    if starts.len() != node.size_in + 1
                        || starts.windows(2).any(|w| w[0] > w[1])
                        || starts.last() != Some(&nnz)
                        || data.len() != nnz
                        || rows.iter().any(|&i| i >= *n_rows)
                    {
                        bail!("node {k}: not a CSC matrix of {} columns", node.size_in);
                    }
                    if let Some(b) = bias {
                        check("the bias", b.len())?;
                    }
                }
                Kind::Lif(lif) => {
                    check("the input", node.size_in)?;
                    lif.check(&check)?;
                }
                Kind::CubaLif { a_syn, w_in, lif } => {
                    check("the input", node.size_in)?;
                    check("a_syn", a_syn.len())?;
                    check("w_in", w_in.len())?;
                    lif.check(&check)?;
                }
            }
            for &(p, delayed) in &node.preds {
                if p >= nodes.len() || (!delayed && p >= k) {
                    bail!("node {k}: source {p} is not a node run before it (or a delayed edge)");
                }
                let got = nodes[p].size_out();
                if got != node.size_in {
                    bail!(
                        "node {k}: source {p} sends {got} values, the node takes {}",
                        node.size_in
                    );
                }
            }
        }
        let mut carried: Vec<usize> = nodes
            .iter()
            .flat_map(|n| {
                n.preds
                    .iter()
                    .filter(|(_, delayed)| *delayed)
                    .map(|(p, _)| *p)
            })
            .collect();
        carried.sort_unstable();
        carried.dedup();
        Ok(NirGraph {
            nodes,
            output,
            carried,
        })
    }

    pub fn n_in(&self) -> usize {
        self.nodes[0].size_in
    }

    pub fn n_out(&self) -> usize {
        self.nodes[self.output].size_out()
    }

    /// A sample's state before its first step.
    pub fn start(&self) -> SampleState {
        let zeros = |n: &Node| vec![0.0; n.size_out()];
        SampleState {
            current: self.nodes.iter().map(zeros).collect(),
            previous: self.nodes.iter().map(zeros).collect(),
            syn: self.nodes.iter().map(zeros).collect(),
            v: self.nodes.iter().map(zeros).collect(),
            spikes: self.nodes.iter().map(zeros).collect(),
            total: Vec::new(),
        }
    }
}

impl Lif {
    fn check(
        &self,
        check: &dyn Fn(&str, usize) -> Result<(), EngineError>,
    ) -> Result<(), EngineError> {
        check("a", self.a.len())?;
        check("r", self.r.len())?;
        check("v_leak", self.leak.len())?;
        check("v_reset", self.reset.len())
    }

    /// `v <- v + a (v_leak - v + r drive)`; a spike where `v > v_threshold` (then `v_reset`).
    fn step(&self, v: &mut [f64], drive: &[f64], out: &mut [f64]) {
        for i in 0..v.len() {
            let vi = v[i] + self.a[i] * (self.leak[i] - v[i] + self.r[i] * drive[i]);
            let spike = vi > self.threshold[i];
            v[i] = if spike { self.reset[i] } else { vi };
            out[i] = if spike { 1.0 } else { 0.0 };
        }
    }
}

/// One sample's state: every node's output this step and the last, its synaptic current and
/// membrane (neurons), and each neuron's spikes so far.
#[derive(Clone, Debug)]
pub struct SampleState {
    current: Vec<Vec<f64>>,
    previous: Vec<Vec<f64>>,
    syn: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
    /// Each neuron node's spikes so far (zeros for the other nodes).
    pub spikes: Vec<Vec<f64>>,
    total: Vec<f64>,
}

impl SampleState {
    /// One step on the input's value `x`; the output node's value is then
    /// [`SampleState::output`].
    fn step(&mut self, graph: &NirGraph, x: &[f64]) {
        self.current[0].copy_from_slice(x);
        for k in 1..graph.nodes.len() {
            let node = &graph.nodes[k];
            let total = &mut self.total;
            total.clear();
            total.resize(node.size_in, 0.0);
            for (i, &(p, delayed)) in node.preds.iter().enumerate() {
                let src = if delayed {
                    &self.previous[p]
                } else {
                    &self.current[p]
                };
                if i == 0 {
                    total.copy_from_slice(src);
                } else {
                    total.iter_mut().zip(src).for_each(|(t, s)| *t += s);
                }
            }
            let out = &mut self.current[k];
            match &node.kind {
                Kind::Input => unreachable!("NirGraph::new puts the one input first"),
                Kind::Output => out.copy_from_slice(total),
                Kind::Affine {
                    starts,
                    rows,
                    data,
                    bias,
                    ..
                } => {
                    // Row i's sum gets its terms in ascending column order, as a CSR row's.
                    out.fill(0.0);
                    for (j, &x) in total.iter().enumerate().filter(|(_, &x)| x != 0.0) {
                        let span = starts[j]..starts[j + 1];
                        for (&i, &w) in rows[span.clone()].iter().zip(&data[span]) {
                            out[i] += w * x;
                        }
                    }
                    if let Some(b) = bias {
                        out.iter_mut().zip(b).for_each(|(y, b)| *y += b);
                    }
                }
                Kind::Lif(lif) => lif.step(&mut self.v[k], total, out),
                Kind::CubaLif { a_syn, w_in, lif } => {
                    let syn = &mut self.syn[k];
                    for i in 0..syn.len() {
                        syn[i] += a_syn[i] * (w_in[i] * total[i] - syn[i]);
                    }
                    lif.step(&mut self.v[k], syn, out);
                }
            }
            if node.is_neuron() {
                self.spikes[k]
                    .iter_mut()
                    .zip(&*out)
                    .for_each(|(s, o)| *s += o);
            }
        }
        for &k in &graph.carried {
            self.previous[k].copy_from_slice(&self.current[k]);
        }
    }
}

/// Run `steps` steps of every sample from its state: `inputs` is row-major
/// `(steps, batch, n_in)`; returns the output node's values, `(steps, batch, n_out)`.
pub fn run_steps(
    graph: &NirGraph,
    states: &mut [SampleState],
    inputs: &[f64],
    cancel: &Cancel,
) -> Result<Vec<f64>, EngineError> {
    let (batch, n_in, n_out) = (states.len(), graph.n_in(), graph.n_out());
    if batch == 0 || n_in == 0 || !inputs.len().is_multiple_of(batch * n_in) {
        bail!(
            "inputs has {} values, not whole steps of {batch} samples of {n_in}",
            inputs.len()
        );
    }
    let steps = inputs.len() / (batch * n_in);
    let outputs = states
        .par_iter_mut()
        .enumerate()
        .map(|(b, state)| {
            let mut out = Vec::with_capacity(steps * n_out);
            for t in 0..steps {
                if t % POLL_STEPS == 0 {
                    cancel.check()?;
                }
                let at = (t * batch + b) * n_in;
                state.step(graph, &inputs[at..at + n_in]);
                out.extend_from_slice(&state.current[graph.output]);
            }
            Ok(out)
        })
        .collect::<Result<Vec<_>, EngineError>>()?;
    let mut joined = vec![0.0; steps * batch * n_out];
    for (b, out) in outputs.iter().enumerate() {
        for t in 0..steps {
            let at = (t * batch + b) * n_out;
            joined[at..at + n_out].copy_from_slice(&out[t * n_out..(t + 1) * n_out]);
        }
    }
    Ok(joined)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lif(n: usize, a: f64, threshold: f64) -> Lif {
        Lif {
            a: vec![a; n],
            r: vec![1.0; n],
            leak: vec![0.0; n],
            threshold: vec![threshold; n],
            reset: vec![0.0; n],
        }
    }

    /// input -> LIF (a = 1: v is the input) -> output, and the LIF's spikes fed back to itself
    /// through an Affine of weight `w` on a delayed edge.
    fn looped(w: f64) -> NirGraph {
        let node = |kind, preds| Node {
            kind,
            size_in: 1,
            preds,
        };
        let affine = Kind::Affine {
            starts: vec![0, 1],
            rows: vec![0],
            data: vec![w],
            n_rows: 1,
            bias: None,
        };
        NirGraph::new(
            vec![
                node(Kind::Input, vec![]),
                node(Kind::Lif(lif(1, 1.0, 0.5)), vec![(0, false), (3, true)]),
                node(Kind::Output, vec![(1, false)]),
                node(affine, vec![(1, false)]),
            ],
            2,
        )
        .unwrap()
    }

    #[test]
    fn a_delayed_edge_delivers_the_previous_step() {
        // The spike of step 0 comes back at step 1 (w = 1), and that one at step 2.
        let graph = looped(1.0);
        let mut states = vec![graph.start()];
        let out = run_steps(&graph, &mut states, &[1.0, 0.0, 0.0], &crate::cancel::NEVER);
        assert_eq!(out.unwrap(), vec![1.0, 1.0, 1.0]);
        let graph = looped(0.25);
        let mut states = vec![graph.start()];
        let out = run_steps(&graph, &mut states, &[1.0, 0.0, 0.0], &crate::cancel::NEVER);
        assert_eq!(out.unwrap(), vec![1.0, 0.0, 0.0]);
        assert_eq!(states[0].spikes[1], vec![1.0]);
    }

    #[test]
    fn samples_keep_their_state_between_calls_and_interleave_by_step() {
        let graph = looped(1.0);
        let mut states = vec![graph.start(), graph.start()];
        let first = run_steps(&graph, &mut states, &[1.0, 0.0], &crate::cancel::NEVER);
        assert_eq!(first.unwrap(), vec![1.0, 0.0]);
        let then = run_steps(&graph, &mut states, &[0.0, 0.0], &crate::cancel::NEVER);
        assert_eq!(then.unwrap(), vec![1.0, 0.0]); // sample 0 still loops, sample 1 is silent
    }

    #[test]
    fn graphs_whose_sizes_disagree_are_refused_by_node() {
        let mut nodes = looped(1.0).nodes;
        nodes[1].kind = Kind::Lif(lif(2, 1.0, 0.5));
        let err = NirGraph::new(nodes, 2).unwrap_err().0;
        assert!(err.contains("node 1"), "{err}");
        let mut nodes = looped(1.0).nodes;
        nodes[2].preds = vec![(3, false)]; // runs after the output
        assert!(NirGraph::new(nodes, 2).unwrap_err().0.contains("node 2"));
    }
}

//! What the interval filter and the exact arithmetic both provide ([`Num`]), and 3-vectors over
//! either ([`V3`]): a decision written once over [`Num`] runs as a fast filter with [`Iv`] and
//! exactly with [`Dyadic`].

use std::cmp::Ordering;

use super::{Dyadic, Iv};

/// Arithmetic both the interval filter and the exact evaluation provide.
pub trait Num: Clone {
    /// The (exact) value of a finite `f64`.
    fn of(x: f64) -> Self;
    /// `self + o`.
    fn plus(&self, o: &Self) -> Self;
    /// `self - o`.
    fn minus(&self, o: &Self) -> Self;
    /// `self * o`.
    fn times(&self, o: &Self) -> Self;
    /// The sign, or `None` when it cannot be told (an interval straddling zero).
    fn sign(&self) -> Option<Ordering>;
}

impl Num for Dyadic {
    fn of(x: f64) -> Self {
        Dyadic::from_f64(x).expect("exact decisions take finite inputs")
    }
    fn plus(&self, o: &Self) -> Self {
        self.add(o)
    }
    fn minus(&self, o: &Self) -> Self {
        self.sub(o)
    }
    fn times(&self, o: &Self) -> Self {
        self.mul(o)
    }
    fn sign(&self) -> Option<Ordering> {
        Some(self.signum())
    }
}

impl Num for Iv {
    fn of(x: f64) -> Self {
        Iv::point(x)
    }
    fn plus(&self, o: &Self) -> Self {
        *self + *o
    }
    fn minus(&self, o: &Self) -> Self {
        *self - *o
    }
    fn times(&self, o: &Self) -> Self {
        *self * *o
    }
    fn sign(&self) -> Option<Ordering> {
        self.sign()
    }
}

/// A 3-vector of [`Num`]s.
#[derive(Clone, Debug)]
pub struct V3<N>(pub [N; 3]);

impl<N: Num> V3<N> {
    /// From `f64` components.
    pub fn of(v: [f64; 3]) -> Self {
        V3(v.map(N::of))
    }
    /// `self - o`.
    pub fn minus(&self, o: &Self) -> Self {
        V3([0, 1, 2].map(|i| self.0[i].minus(&o.0[i])))
    }
    /// The dot product.
    pub fn dot(&self, o: &Self) -> N {
        self.0[0]
            .times(&o.0[0])
            .plus(&self.0[1].times(&o.0[1]))
            .plus(&self.0[2].times(&o.0[2]))
    }
    /// The cross product.
    pub fn cross(&self, o: &Self) -> Self {
        let (a, b) = (&self.0, &o.0);
        V3([
            a[1].times(&b[2]).minus(&a[2].times(&b[1])),
            a[2].times(&b[0]).minus(&a[0].times(&b[2])),
            a[0].times(&b[1]).minus(&a[1].times(&b[0])),
        ])
    }
}

//! Seeded sensor noise: a deterministic Gaussian generator and a per-channel noise
//! model applied to a [`Recording`](super::Recording).

use super::experiment::{Recording, Sample};
use dyngen_reference::SplitMix64;
use nalgebra::Vector3;

/// Standard normal draws by the Box–Muller transform over [`SplitMix64`]: from two
/// uniforms `u1 = 1 − U ∈ (0, 1]`, `u2 = U ∈ [0, 1)` (in that order),
/// `z1 = √(−2 ln u1) cos 2πu2`, then `z2 = √(−2 ln u1) sin 2πu2` on the next call.
/// The stream for a seed is fixed forever, like [`SplitMix64`]'s.
#[derive(Clone, Debug)]
pub struct Gaussian {
    rng: SplitMix64,
    spare: Option<f64>,
}

impl Gaussian {
    pub fn new(seed: u64) -> Gaussian {
        Gaussian {
            rng: SplitMix64::new(seed),
            spare: None,
        }
    }

    /// One draw from `N(0, 1)`.
    pub fn standard(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let u1 = 1.0 - self.rng.next_f64();
        let u2 = self.rng.next_f64();
        let radius = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(radius * s);
        radius * c
    }

    /// One draw from `N(0, σ²)`.
    pub fn normal(&mut self, sigma: f64) -> f64 {
        sigma * self.standard()
    }
}

/// How large one channel's noise is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Sigma {
    /// No noise.
    #[default]
    None,
    /// A fixed standard deviation, in the channel's SI unit.
    Absolute(f64),
    /// A fraction of the sensor's RMS over the noise-free recording: `0.01` is
    /// "1 % noise". A sensor is one joint's scalar, or one body's 3-vector (the RMS
    /// pools its three axes, so a gyro whose x axis sees no motion still gets noise
    /// on x).
    Relative(f64),
    /// A fraction of each recorded curve's own RMS: a 3-vector's x, y and z each get
    /// `level ×` their own RMS (for scalars the same as [`Sigma::Relative`]). This is
    /// "1 % noise on every measured channel" read component by component; an axis
    /// that barely moves gets correspondingly little noise.
    RelativePerAxis(f64),
}

impl Sigma {
    fn resolve(self, rms: f64) -> f64 {
        match self {
            Sigma::None => 0.0,
            Sigma::Absolute(s) => s,
            Sigma::Relative(r) | Sigma::RelativePerAxis(r) => r * rms,
        }
    }

    /// [`Sigma::Relative`] becomes [`Sigma::RelativePerAxis`]; the others stay.
    fn per_axis(self) -> Sigma {
        match self {
            Sigma::Relative(r) => Sigma::RelativePerAxis(r),
            s => s,
        }
    }
}

/// The channels of a [`Recording`] that can carry noise, in the fixed order their
/// Gaussian streams are seeded (see [`NoiseModel::apply`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channel {
    Q,
    V,
    A,
    Tau,
    Cardano,
    CardanoRates,
    AngularVelocity,
    AngularAcceleration,
    ComAcceleration,
    JointForce,
    JointMoment,
    ResultantForce,
    ResultantMoment,
}

impl Channel {
    pub const ALL: [Channel; 13] = [
        Channel::Q,
        Channel::V,
        Channel::A,
        Channel::Tau,
        Channel::Cardano,
        Channel::CardanoRates,
        Channel::AngularVelocity,
        Channel::AngularAcceleration,
        Channel::ComAcceleration,
        Channel::JointForce,
        Channel::JointMoment,
        Channel::ResultantForce,
        Channel::ResultantMoment,
    ];
}

/// Independent zero-mean Gaussian noise per channel of a [`Recording`]. Body
/// resultants are treated as measured by their own sensors: their noise is drawn
/// independently of the joint wrenches' (recombining noisy joint wrenches would
/// amplify the noise on small resultant moments by the ratio of joint to resultant
/// moments, often 100×, which no 6-axis sensor on the body would).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NoiseModel {
    pub q: Sigma,
    pub v: Sigma,
    pub a: Sigma,
    pub tau: Sigma,
    pub cardano: Sigma,
    pub cardano_rates: Sigma,
    pub angular_velocity: Sigma,
    pub angular_acceleration: Sigma,
    pub com_acceleration: Sigma,
    pub joint_force: Sigma,
    pub joint_moment: Sigma,
    pub resultant_force: Sigma,
    pub resultant_moment: Sigma,
}

impl NoiseModel {
    /// No noise anywhere.
    pub fn none() -> NoiseModel {
        NoiseModel::default()
    }

    /// The same relative level on every channel: `relative(0.01)` is 1 % noise.
    pub fn relative(level: f64) -> NoiseModel {
        let s = Sigma::Relative(level);
        NoiseModel {
            q: s,
            v: s,
            a: s,
            tau: s,
            cardano: s,
            cardano_rates: s,
            angular_velocity: s,
            angular_acceleration: s,
            com_acceleration: s,
            joint_force: s,
            joint_moment: s,
            resultant_force: s,
            resultant_moment: s,
        }
    }

    /// The paper's MIM measurements only (kinematics of each body and its resultant
    /// wrench), at one relative level; joint quantities stay exact.
    pub fn mim(level: f64) -> NoiseModel {
        let s = Sigma::Relative(level);
        NoiseModel {
            cardano: s,
            cardano_rates: s,
            angular_velocity: s,
            angular_acceleration: s,
            com_acceleration: s,
            resultant_force: s,
            resultant_moment: s,
            ..NoiseModel::default()
        }
    }

    /// The same model with every [`Sigma::Relative`] channel made
    /// [`Sigma::RelativePerAxis`]: `NoiseModel::mim(0.01).per_axis()` is 1 % of each
    /// measured curve's own RMS.
    pub fn per_axis(self) -> NoiseModel {
        NoiseModel {
            q: self.q.per_axis(),
            v: self.v.per_axis(),
            a: self.a.per_axis(),
            tau: self.tau.per_axis(),
            cardano: self.cardano.per_axis(),
            cardano_rates: self.cardano_rates.per_axis(),
            angular_velocity: self.angular_velocity.per_axis(),
            angular_acceleration: self.angular_acceleration.per_axis(),
            com_acceleration: self.com_acceleration.per_axis(),
            joint_force: self.joint_force.per_axis(),
            joint_moment: self.joint_moment.per_axis(),
            resultant_force: self.resultant_force.per_axis(),
            resultant_moment: self.resultant_moment.per_axis(),
        }
    }

    pub fn sigma(&self, channel: Channel) -> Sigma {
        match channel {
            Channel::Q => self.q,
            Channel::V => self.v,
            Channel::A => self.a,
            Channel::Tau => self.tau,
            Channel::Cardano => self.cardano,
            Channel::CardanoRates => self.cardano_rates,
            Channel::AngularVelocity => self.angular_velocity,
            Channel::AngularAcceleration => self.angular_acceleration,
            Channel::ComAcceleration => self.com_acceleration,
            Channel::JointForce => self.joint_force,
            Channel::JointMoment => self.joint_moment,
            Channel::ResultantForce => self.resultant_force,
            Channel::ResultantMoment => self.resultant_moment,
        }
    }

    /// A noisy copy of `recording` (time stamps stay exact). Seeding: a
    /// [`SplitMix64`] seeded with `seed` gives one seed per channel, in the order of
    /// [`Channel::ALL`]; each channel's [`Gaussian`] stream then runs over samples in
    /// time order, within a sample over joints or bodies, within a 3-vector over x,
    /// y, z. So one channel's noise does not change when another's σ does. σ of a
    /// [`Sigma::Relative`] channel comes from the RMS of the noise-free input.
    pub fn apply(&self, recording: &Recording, seed: u64) -> Recording {
        let mut seeds = SplitMix64::new(seed);
        let mut out = recording.clone();
        for channel in Channel::ALL {
            let channel_seed = seeds.next_u64();
            let sigma = self.sigma(channel);
            if sigma == Sigma::None {
                continue;
            }
            let mut rng = Gaussian::new(channel_seed);
            match channel_kind(channel) {
                Kind::Scalar(get, get_mut) => {
                    let sensors = recording.samples.first().map_or(0, |s| get(s).len());
                    let sigmas: Vec<f64> = (0..sensors)
                        .map(|k| sigma.resolve(rms(recording.samples.iter().map(|s| get(s)[k]))))
                        .collect();
                    for sample in &mut out.samples {
                        for (x, s) in get_mut(sample).iter_mut().zip(&sigmas) {
                            *x += rng.normal(*s);
                        }
                    }
                }
                Kind::Vector(get, get_mut) => {
                    let sensors = recording.samples.first().map_or(0, |s| count_vectors(s, channel));
                    let sigmas: Vec<[f64; 3]> = (0..sensors)
                        .map(|k| {
                            let axis = |c: usize| rms(recording.samples.iter().map(|s| get(s, k)[c]));
                            if let Sigma::RelativePerAxis(_) = sigma {
                                [0, 1, 2].map(|c| sigma.resolve(axis(c)))
                            } else {
                                let values = recording.samples.iter().flat_map(|s| {
                                    let x = get(s, k);
                                    [x.x, x.y, x.z]
                                });
                                [sigma.resolve(rms(values)); 3]
                            }
                        })
                        .collect();
                    for sample in &mut out.samples {
                        for (k, s) in sigmas.iter().enumerate() {
                            let x = get_mut(sample, k);
                            for c in 0..3 {
                                x[c] += rng.normal(s[c]);
                            }
                        }
                    }
                }
            }
        }
        out
    }
}

/// Root mean square of a sequence (0 for an empty one).
fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
    if count == 0 {
        0.0
    } else {
        (sum / count as f64).sqrt()
    }
}

type ScalarGet = fn(&Sample) -> &[f64];
type ScalarGetMut = fn(&mut Sample) -> &mut [f64];
type VectorGet = fn(&Sample, usize) -> Vector3<f64>;
type VectorGetMut = fn(&mut Sample, usize) -> &mut Vector3<f64>;

enum Kind {
    Scalar(ScalarGet, ScalarGetMut),
    Vector(VectorGet, VectorGetMut),
}

fn count_vectors(sample: &Sample, channel: Channel) -> usize {
    match channel {
        Channel::JointForce | Channel::JointMoment => sample.joint_wrenches.len(),
        _ => sample.bodies.len(),
    }
}

fn channel_kind(channel: Channel) -> Kind {
    match channel {
        Channel::Q => Kind::Scalar(|s| &s.q, |s| &mut s.q),
        Channel::V => Kind::Scalar(|s| &s.v, |s| &mut s.v),
        Channel::A => Kind::Scalar(|s| &s.a, |s| &mut s.a),
        Channel::Tau => Kind::Scalar(|s| &s.tau, |s| &mut s.tau),
        Channel::Cardano => Kind::Vector(|s, k| s.bodies[k].cardano, |s, k| &mut s.bodies[k].cardano),
        Channel::CardanoRates => Kind::Vector(|s, k| s.bodies[k].cardano_rates, |s, k| &mut s.bodies[k].cardano_rates),
        Channel::AngularVelocity => Kind::Vector(
            |s, k| s.bodies[k].angular_velocity,
            |s, k| &mut s.bodies[k].angular_velocity,
        ),
        Channel::AngularAcceleration => Kind::Vector(
            |s, k| s.bodies[k].angular_acceleration,
            |s, k| &mut s.bodies[k].angular_acceleration,
        ),
        Channel::ComAcceleration => Kind::Vector(
            |s, k| s.bodies[k].com_acceleration,
            |s, k| &mut s.bodies[k].com_acceleration,
        ),
        Channel::JointForce => Kind::Vector(|s, k| s.joint_wrenches[k].force, |s, k| &mut s.joint_wrenches[k].force),
        Channel::JointMoment => Kind::Vector(
            |s, k| s.joint_wrenches[k].torque,
            |s, k| &mut s.joint_wrenches[k].torque,
        ),
        Channel::ResultantForce => Kind::Vector(
            |s, k| s.bodies[k].resultant.force,
            |s, k| &mut s.bodies[k].resultant.force,
        ),
        Channel::ResultantMoment => Kind::Vector(
            |s, k| s.bodies[k].resultant.torque,
            |s, k| &mut s.bodies[k].resultant.torque,
        ),
    }
}

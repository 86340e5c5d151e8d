//! Online identification of a changing body: one body's θ jumps mid-recording (a
//! payload is picked up) and two estimators follow it sample by sample, the
//! generalising NIM on the window that ends at each sample and recursive least
//! squares with a forgetting factor on the same body equations `A_i θ_i = [F; M]`.

use super::identifier::{BodySample, Nim};
use super::NimError;
use dyngen_identify::simulate::Recording;
use dyngen_identify::Rls;

/// Settings of [`track`].
#[derive(Clone, Debug, PartialEq)]
pub struct Tracking {
    /// The body whose θ changes (0-based).
    pub body: usize,
    /// The first sample with the new θ.
    pub change: usize,
    /// θ before and after the change.
    pub before: [f64; 4],
    pub after: [f64; 4],
    /// RLS forgetting factor per equation row (six rows per sample).
    pub lambda: f64,
    /// An estimate has settled when its relative error stays within these until
    /// the end of the recording: `(mass, principal moments)`.
    pub tolerance: (f64, f64),
}

/// Both estimators at every sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    pub t: Vec<f64>,
    /// NIM on the window ending at each sample (`None` before the first full
    /// window, and for parameters it does not predict).
    pub nim: Vec<[Option<f64>; 4]>,
    /// RLS after each sample, started from the draws' centre (`Nim::nominal`).
    pub rls: Vec<[f64; 4]>,
    pub truth: Vec<[f64; 4]>,
}

/// How one estimator followed the change, for the mass and the worst principal
/// moment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackingSummary {
    /// Time from the change until the estimate's relative error stays within the
    /// tolerance to the end; `None`: it never settles.
    pub delay_mass: Option<f64>,
    pub delay_moments: Option<f64>,
    /// RMS relative error over the stretch before the change (from the first full
    /// window), and over the second half of the stretch after it.
    pub error_before: (f64, f64),
    pub error_after: (f64, f64),
    /// Seconds of computation per sample (for both estimators alike: the window
    /// prediction, or one RLS update of six rows).
    pub seconds_per_sample: f64,
}

/// Runs both estimators over `recording` (whose `tracking.body` changes θ at
/// `tracking.change`). Errors when the body or the change is out of range, or RLS
/// rejects the data (non-finite values).
pub fn track(nim: &Nim, recording: &Recording, tracking: &Tracking) -> Result<(Track, [TrackingSummary; 2]), NimError> {
    let i = tracking.body;
    if i >= nim.n_bodies() || i >= recording.nv() || tracking.change >= recording.len() {
        return Err(NimError::InvalidOption {
            field: "tracking",
            reason: format!(
                "body {i} and change at sample {} outside {} bodies and {} samples",
                tracking.change,
                recording.nv().min(nim.n_bodies()),
                recording.len()
            ),
        });
    }
    let w = nim.window;
    let rls_error = |e: dyngen_identify::IdentifyError| NimError::InvalidOption {
        field: "recursive least squares",
        reason: e.to_string(),
    };
    let mut rls = Rls::with_initial(&nim.nominal[4 * i..4 * i + 4], tracking.lambda, 1e3).map_err(rls_error)?;
    let mut predictor = nim.predictor();
    let mut window: Vec<BodySample> = Vec::with_capacity(w);
    let mut out = Track {
        t: Vec::with_capacity(recording.len()),
        nim: Vec::with_capacity(recording.len()),
        rls: Vec::with_capacity(recording.len()),
        truth: Vec::with_capacity(recording.len()),
    };
    let (mut nim_time, mut rls_time) = (0.0, 0.0);
    for k in 0..recording.len() {
        let sample = BodySample::from_recording(recording, k, i);
        if window.len() == w {
            window.remove(0);
        }
        window.push(sample);
        let mut theta = [None; 4];
        if window.len() == w {
            let start = std::time::Instant::now();
            nim.predict(i, &window, &mut predictor, &mut theta);
            nim_time += start.elapsed().as_secs_f64();
        }
        let start = std::time::Instant::now();
        let block = recording.body_regressor(k, i);
        let y = recording.body_wrench(k, i);
        for r in 0..6 {
            rls.update(&block.row(r), y[r]).map_err(rls_error)?;
        }
        rls_time += start.elapsed().as_secs_f64();
        out.t.push(recording.samples[k].t);
        out.nim.push(theta);
        out.rls.push(rls.estimate().try_into().expect("4 parameters"));
        out.truth.push(if k < tracking.change {
            tracking.before
        } else {
            tracking.after
        });
    }
    let nim_values: Vec<[Option<f64>; 4]> = out.nim.clone();
    let rls_values: Vec<[Option<f64>; 4]> = out.rls.iter().map(|x| x.map(Some)).collect();
    let windows = (recording.len() - w + 1) as f64;
    Ok((
        out.clone(),
        [
            summarise(&out, &nim_values, tracking, w, nim_time / windows),
            summarise(&out, &rls_values, tracking, w, rls_time / recording.len() as f64),
        ],
    ))
}

/// Delays and errors of one estimator's values (see [`TrackingSummary`]).
fn summarise(
    track: &Track,
    values: &[[Option<f64>; 4]],
    tracking: &Tracking,
    window: usize,
    seconds_per_sample: f64,
) -> TrackingSummary {
    let relative = |k: usize, p: usize| values[k][p].map(|v| dyngen_identify::relative_error(v, track.truth[k][p]));
    // Parameters the estimator does not give are left out of the moment figures.
    let moments: Vec<usize> = (1..4).filter(|&p| values.iter().any(|v| v[p].is_some())).collect();
    let error = |k: usize, params: &[usize]| {
        params
            .iter()
            .map(|&p| relative(k, p).unwrap_or(f64::INFINITY))
            .fold(0.0, f64::max)
    };
    let settled = |params: &[usize], tolerance: f64| -> Option<f64> {
        if params.is_empty() {
            return None;
        }
        let end = values.len();
        let mut first = end;
        for k in (tracking.change..end).rev() {
            if error(k, params) <= tolerance {
                first = k;
            } else {
                break;
            }
        }
        (first < end).then(|| track.t[first] - track.t[tracking.change])
    };
    let rms = |range: std::ops::Range<usize>, params: &[usize]| {
        let mut sum = 0.0;
        let mut count = 0;
        for k in range {
            for &p in params {
                if let Some(r) = relative(k, p) {
                    sum += r * r;
                    count += 1;
                }
            }
        }
        if count == 0 {
            f64::NAN
        } else {
            (sum / count as f64).sqrt()
        }
    };
    let start = (window - 1).min(tracking.change);
    let tail = tracking.change + (values.len() - tracking.change) / 2;
    TrackingSummary {
        delay_mass: settled(&[0], tracking.tolerance.0),
        delay_moments: settled(&moments, tracking.tolerance.1),
        error_before: (rms(start..tracking.change, &[0]), rms(start..tracking.change, &moments)),
        error_after: (rms(tail..values.len(), &[0]), rms(tail..values.len(), &moments)),
        seconds_per_sample,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NimConfig;
    use dyngen_identify::simulate::{record, Experiment};
    use dyngen_reference::Reference;

    #[test]
    fn both_estimators_follow_a_change_and_bad_settings_are_errors() {
        let model = dyngen_model::parse_urdf(include_str!("../../tests/fixtures/paper6.urdf")).unwrap();
        let robot = Reference::new(&model);
        let nominal = dyngen_model::principal_params(&model);
        let experiment = Experiment::paper(&model);
        let base = record(&robot, &model.standard_params(), &experiment);
        let mut config = NimConfig {
            draws: 40,
            window: 10,
            ..NimConfig::default()
        };
        config.train.max_steps = 100;
        let (nim, _) = Nim::train("paper6", &base, &nominal, &config, &|_| {}).unwrap();

        // The flange 10 % heavier from sample 60 on.
        let mut heavier = nominal.clone();
        for x in &mut heavier[20..24] {
            *x *= 1.1;
        }
        let changed = record(
            &robot,
            &dyngen_reference::principal_params_to_standard(&model, &heavier),
            &experiment,
        );
        let mut spliced = base.clone();
        spliced.samples[60..].clone_from_slice(&changed.samples[60..]);
        let tracking = Tracking {
            body: 5,
            change: 60,
            before: nominal[20..24].try_into().unwrap(),
            after: heavier[20..24].try_into().unwrap(),
            lambda: 1.0 - 1.0 / 60.0,
            tolerance: (0.02, 0.05),
        };
        let (followed, [by_nim, by_rls]) = track(&nim, &spliced, &tracking).unwrap();
        assert_eq!(followed.t.len(), 101);
        assert!(followed.nim[..9].iter().all(|v| v.iter().all(Option::is_none)));
        assert!(followed.nim[9..].iter().all(|v| v.iter().all(Option::is_some)));
        assert_eq!(
            (followed.truth[59], followed.truth[60]),
            (tracking.before, tracking.after)
        );
        // Noise-free data: RLS is exact before the change and settles after it.
        assert!(
            by_rls.error_before.0 < 1e-9 && by_rls.error_before.1 < 1e-9,
            "{by_rls:?}"
        );
        let delay = by_rls.delay_mass.expect("RLS settles");
        assert!(delay > 0.0 && delay < 0.8, "{by_rls:?}");
        assert!(by_nim.seconds_per_sample > 0.0);

        let err = track(
            &nim,
            &spliced,
            &Tracking {
                body: 6,
                ..tracking.clone()
            },
        )
        .unwrap_err();
        assert!(
            err.to_string()
                .contains("body 6 and change at sample 60 outside 6 bodies"),
            "{err}"
        );
        let err = track(
            &nim,
            &spliced,
            &Tracking {
                lambda: 0.0,
                ..tracking
            },
        )
        .unwrap_err();
        assert!(err.to_string().contains("forgetting factor"), "{err}");
    }
}

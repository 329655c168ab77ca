//! The diagnosis on the test worlds' records (KVLCC2, Mariner, the Seiun Maru, the container
//! ship, the Esso Osaka): what their channels show of a current and the wind, and trials
//! sailed with other commands than the reference.

use super::*;

/// Records of a test world as `bench/worlds/run.sh` sails them: 1 800 s of the world's
/// identification input with the suite's trial noise, the hidden effects given.
pub(crate) fn world_records(
    kind: crate::sim::WorldKind,
    effects: Vec<SimEffect>,
    seeds: &[u64],
) -> Vec<Record> {
    world_records_with(kind, effects, seeds, false)
}

/// A test world, its effect-free reference (seeds 900–902, sailed as [`world_records`]
/// sails them) and the model `identify` writes for it.
fn world_reference(kind: crate::sim::WorldKind) -> (crate::sim::World, Vec<Record>, Model) {
    let w = crate::sim::World::new(kind, None).unwrap();
    let reference = world_records(kind, Vec::new(), &[900, 901, 902]);
    let model = identify(&reference);
    (w, reference, model)
}

/// [`world_records`], with the anemometer's columns logged or not.
fn world_records_with(
    kind: crate::sim::WorldKind,
    effects: Vec<SimEffect>,
    seeds: &[u64],
    log_wind: bool,
) -> Vec<Record> {
    noisy_records(kind, effects, seeds, log_wind, [0.03, 0.2, 0.02])
}

/// [`world_records_with`], with gyro, heading and speed noise `noise` (°/s, °, m/s).
pub(super) fn noisy_records(
    kind: crate::sim::WorldKind,
    effects: Vec<SimEffect>,
    seeds: &[u64],
    log_wind: bool,
    noise: [f64; 3],
) -> Vec<Record> {
    let w = crate::sim::World::new(kind, None).unwrap();
    let sc = Scenario {
        n_samples: 1800,
        input: w.default_input(),
        noise: noise_spec(noise),
        effects,
        log_wind,
        ..Scenario::default()
    };
    w.simulate_many(&sc, seeds).unwrap()
}

/// Gyro, heading and speed noise `noise` (°/s, °, m/s) as a [`NoiseSpec`].
fn noise_spec(noise: [f64; 3]) -> NoiseSpec {
    NoiseSpec {
        gyro_std_degps: noise[0],
        heading_std_deg: noise[1],
        speed_std_mps: noise[2],
    }
}

/// The records of `sc` on world `w`, the anemometer logged, with gyro, heading and speed
/// noise `noise` (°/s, °, m/s): the reference as the suite sails it with less noise than the
/// trials. The built-in ship's course over ground is its navigation part's, added as
/// `simulate` writes it beside the record (the anemometer's true wind needs it).
fn sailed(w: &crate::sim::World, sc: Scenario, noise: [f64; 3], seeds: &[u64]) -> Vec<Record> {
    let sc = Scenario {
        noise: noise_spec(noise),
        log_wind: true,
        ..sc
    };
    if w.kind() != crate::sim::WorldKind::Lng {
        return w.simulate_many(&sc, seeds).unwrap();
    }
    seeds
        .iter()
        .map(|&seed| {
            let (mut r, nav) =
                crate::sim::simulate_with_nav(&Ship::default_lng(), &sc, seed).unwrap();
            r.cog = Some(nav.cog_deg);
            r.name = format!("{}-{seed}", sc.name);
            r
        })
        .collect()
}

#[test]
fn the_anemometer_shows_wind_and_not_a_current() {
    // Mariner at half the canonical wind: its yaw moment is too weak for the yaw channel
    // and its leeway moves the ground track like a current. The anemometer's apparent
    // wind with the ground velocity gives the true wind itself; a current carries ship
    // and anemometer alike and leaves none
    use super::anemometer::anemometer_evidence;
    use crate::sim::{World, WorldKind};
    let k = WorldKind::Mariner;
    let w = World::new(k, None).unwrap();
    let hidden = w.hidden(EffectKind::Wind, 0.5);
    let SimEffect::Wind {
        speed_mps,
        from_deg,
    } = hidden
    else {
        panic!("{hidden:?}")
    };
    let reference = world_records_with(k, Vec::new(), &[900, 901, 902], true);
    let wind = world_records_with(k, vec![hidden], &[101, 102, 103], true);
    let a = anemometer_evidence(&wind, &reference).unwrap();
    let (speed, from) = a.speed_from();
    println!("true wind {speed:.2} m/s from {from:.0}° (hidden {speed_mps:.2}, {from_deg}); {a:?}");
    // the gusts multiply the mean wind by 1 + g, g of mean zero
    assert!((speed - speed_mps).abs() < 0.05 * speed_mps, "{speed}");
    assert!((from - from_deg).abs() < 3.0, "{from}");
    assert!(a.p < 1e-12, "{a:?}");
    // the trials' wind, not the reference's; the other way round (a wind the reference
    // sailed in, calm trials) the change is the reference's
    assert!(!a.the_references(), "{a:?}");
    let back = anemometer_evidence(&reference, &wind).unwrap();
    assert!(back.the_references() && back.p < 1e-12, "{back:?}");
    assert!(
        (back.own[1] - speed).abs() < 0.01 * speed && back.own[0] < 0.1,
        "{back:?}"
    );
    // the same records as a ship's NMEA log (HDT, ROT, RSA, VTG, MWV): the course over
    // ground the log carries reaches the record, and the anemometer shows the same wind
    let opts = crate::io::nmea::NmeaOptions {
        clock: crate::io::nmea::Clock::Rate(1.0),
        ..Default::default()
    };
    let as_log = |recs: &[Record]| -> Vec<Record> {
        recs.iter()
            .map(|r| {
                let log = crate::io::nmea::tests::log_of(r);
                crate::io::nmea::parse_nmea(&log, "t.nmea".as_ref(), "t", &opts).unwrap()
            })
            .collect()
    };
    let b = anemometer_evidence(&as_log(&wind), &as_log(&reference)).expect("course read");
    let (s2, f2) = b.speed_from();
    assert!(
        (s2 - speed).abs() < 0.02 * speed && (f2 - from).abs() < 1.0,
        "{b:?}"
    );
    assert!(b.p < 1e-12, "{b:?}");
    let level = 0.01 / 10.0;
    for (what, effects) in [
        ("a current", vec![w.hidden(EffectKind::Current, 1.0)]),
        ("nothing", Vec::new()),
    ] {
        let t = world_records_with(k, effects, &[201, 202, 203], true);
        let a = anemometer_evidence(&t, &reference).unwrap();
        println!("{what}: {:?}, p = {:.3}", a.speed_from(), a.p);
        assert!(a.p > level && a.speed_from().0 < 0.1, "{what}: {a:?}");
    }
    // without the columns, or without a course, no anemometer evidence
    assert!(anemometer_evidence(&world_records(k, Vec::new(), &[5]), &[]).is_none());
    let mut no_course = wind.clone();
    no_course[0].cog = None;
    assert!(anemometer_evidence(&no_course, &reference).is_none());
}

#[test]
fn course_over_ground_shows_a_current_a_tanker_turns_too_slowly_for() {
    // KVLCC2 at full scale: in 1 800 s its heading spans 120–200° while its speed falls
    // with an ≈ 850-s surge lag, so speed over ground alone resolves a current poorly;
    // across the track the course over ground shows it, in speed and direction, finer
    use crate::sim::{World, WorldKind};
    let level = 0.01 / 10.0;
    let w = World::new(WorldKind::Kvlcc2, None).unwrap();
    let hidden = w.hidden(EffectKind::Current, 1.0);
    let SimEffect::Current {
        speed_mps,
        towards_deg,
    } = hidden
    else {
        panic!("{hidden:?}")
    };
    let reference = world_records(WorldKind::Kvlcc2, Vec::new(), &[900, 901, 902]);
    let trial = world_records(WorldKind::Kvlcc2, vec![hidden], &[101, 102, 103]);
    let s = sog_evidence(&trial, &reference, 1).unwrap();
    let c = s.cross.unwrap();
    let (speed, dir) = c.speed_dir();
    println!("{speed:.3} m/s towards {dir:.1}° (hidden {speed_mps:.3}, {towards_deg}); {c:?}");
    assert!(
        (speed - speed_mps).abs() < 0.1 * speed_mps,
        "{speed} vs {speed_mps}"
    );
    assert!((dir - towards_deg).abs() < 5.0, "{dir}");
    assert!(s.test(true).2 < 1e-9, "{s:?}");
    // speed over ground alone (the slow fall of speed over the turning history taken by
    // the surge lags and the slope on the heading turned through): the hidden current's
    // size, but in its worst direction no finer than 0.5 m/s
    let bare = |v: &[Record]| -> Vec<Record> {
        let no_cog = |r: &Record| Record {
            cog: None,
            ..r.clone()
        };
        v.iter().map(no_cog).collect()
    };
    let along = sog_evidence(&bare(&trial), &bare(&reference), 1).unwrap();
    assert!(along.cross.is_none());
    assert!(
        (along.amp1 - speed_mps).abs() < 0.05 * speed_mps,
        "{along:?}"
    );
    assert!(along.smallest_current(level) > 0.5, "{along:?}");
    assert!(
        s.smallest_current(level) < 0.2 * along.smallest_current(level),
        "{s:?}"
    );
    // effect-free trials sailed with other inputs and noise: no current
    let none = world_records(WorldKind::Kvlcc2, Vec::new(), &[201, 202, 203]);
    let n = sog_evidence(&none, &reference, 1).unwrap();
    let nc = n.cross.unwrap();
    assert!(n.test(true).2 > level, "{n:?}");
    assert!(nc.speed_dir().0 < 0.1, "{nc:?}");
    // and the records say how small a current they would show: under 1.5 m/s, where the
    // records turn through 126–197° (those with the current, 228–271°: 0.1 m/s)
    assert!(s.smallest_current(level) < 0.12, "{s:?}");
    assert!(
        n.smallest_current(level) < 1.5,
        "{}",
        n.smallest_current(level)
    );
}

/// The suite's effect-free ±20° zig-zag case on world `kind`, seed `s` (`bench/worlds/run.sh
/// --trial-input zigzag:20/20 --log-wind`): the model identified on three PRBS reference
/// records (seeds 900–902), the reference, and three zig-zag trials (seeds 100·s … 100·s + 2)
/// with the trials' noise ([`sailed`]).
fn zig_zags_against_prbs(kind: crate::sim::WorldKind, s: u64) -> (Model, Vec<Record>, Vec<Record>) {
    zig_zags_against_prbs_in(kind, s, None)
}

/// [`zig_zags_against_prbs`] with `hidden` (the world's own version at full strength) in the
/// trials.
fn zig_zags_against_prbs_in(
    kind: crate::sim::WorldKind,
    s: u64,
    hidden: Option<EffectKind>,
) -> (Model, Vec<Record>, Vec<Record>) {
    zig_zags_against(kind, s, hidden, false)
}

/// As [`zig_zags_against_prbs_in`], the reference sailed with the world's own input or,
/// with `zig_zag_reference`, with the trials' ±20° zig-zags.
fn zig_zags_against(
    kind: crate::sim::WorldKind,
    s: u64,
    hidden: Option<EffectKind>,
    zig_zag_reference: bool,
) -> (Model, Vec<Record>, Vec<Record>) {
    use crate::sim::{InputSpec, World};
    let w = World::new(kind, None).unwrap();
    let effects: Vec<SimEffect> = hidden.map(|k| w.hidden(k, 1.0)).into_iter().collect();
    let sail = |input: InputSpec, effects: Vec<SimEffect>, noise: [f64; 3], seeds: &[u64]| {
        let sc = Scenario {
            n_samples: 1800,
            input,
            effects,
            ..Scenario::default()
        };
        sailed(&w, sc, noise, seeds)
    };
    let zigzag = InputSpec::ZigZag {
        delta_deg: 20.0,
        psi_deg: 20.0,
    };
    // as the suite sails them: the reference with less noise than the trials
    let reference = sail(
        if zig_zag_reference {
            zigzag.clone()
        } else {
            w.default_input()
        },
        Vec::new(),
        [0.02, 0.1, 0.0],
        &[900, 901, 902],
    );
    let model = identify(&reference);
    let trials = sail(
        zigzag,
        effects,
        [0.03, 0.2, 0.02],
        &[100 * s, 100 * s + 1, 100 * s + 2],
    );
    (model, reference, trials)
}

/// `diagnose` with the default configuration at `seed`, and the ranking's row of `effect`
/// (printed with the verdict and the explanation).
fn diagnosed_at(
    model: &Model,
    reference: &[Record],
    trials: &[Record],
    seed: u64,
    effect: &str,
) -> (super::Diagnosis, Ranked) {
    let cfg = DiagnoseConfig {
        seed,
        ..DiagnoseConfig::default()
    };
    let d = diagnose(model, reference, trials, &[], &cfg).unwrap();
    let row = d
        .ranking
        .iter()
        .find(|r| r.effect == effect)
        .unwrap()
        .clone();
    println!("{} {row:?}\n{}", d.verdict, d.explanation);
    (d, row)
}

#[test]
fn zig_zag_trials_against_a_prbs_reference_are_judged_with_the_hulls_own_physics() {
    // KVLCC2 at full scale, effect-free ±20° zig-zags against its PRBS reference: at the
    // zig-zag's turn rates the linear model meets the hull's own nonlinearity as it never
    // does on the reference, and with nulls simulated from the linear model the trials read
    // as a dead band or nonlinear damping (`bench/worlds/run.sh --trial-input zigzag:20/20`:
    // 3 of 3 seeds). The nulls now simulate the hull physics the reference shows of its own
    let (model, reference, trials) = zig_zags_against_prbs(crate::sim::WorldKind::Kvlcc2, 1);
    let cfg = DiagnoseConfig::default();
    let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
    let top: Vec<(&str, f64, f64)> = d
        .ranking
        .iter()
        .take(4)
        .map(|r| (r.effect.as_str(), r.statistic, r.p_value))
        .collect();
    println!("{} {top:?}\n{}", d.verdict, d.explanation);
    let hull = d
        .caveats
        .iter()
        .find_map(|c| match c {
            Caveat::OtherManoeuvre { distance, hull } => Some((*distance, hull.clone())),
            _ => None,
        })
        .expect("other-manoeuvre caveat");
    assert!(hull.0 > 0.7, "{hull:?}");
    assert!(hull.1.iter().any(|h| h.contains("damping")), "{hull:?}");
    assert!(
        d.explanation.contains("simulate the hull physics"),
        "{}",
        d.explanation
    );
    assert_eq!(d.verdict, "none", "{}", d.explanation);
}

#[test]
fn zig_zags_that_each_hold_one_course_are_not_read_as_a_current_from_the_yaw_channel() {
    // the built-in ship's effect-free ±20° zig-zags against its PRBS reference, as
    // `bench/worlds/run.sh --trial-input zigzag:20/20 --log-wind` sails them (seed 1): each
    // record swings about its own course, so a heading harmonic is that record's offset and
    // turn, and so is the linear model's mismatch with the hull in every swing. The yaw
    // channel read a current at p = 3.5e-5 (13 % of the 50-step error energy) while the
    // ground velocity showed none (χ² = 3.7, 2 df) and the anemometer no wind
    let (model, reference, trials) = zig_zags_against_prbs(crate::sim::WorldKind::Lng, 1);
    let sep = super::super::separation::heading_separation(&trials).unwrap();
    assert!(sep < 0.005, "{sep}");
    let (d, current) = diagnosed_at(&model, &reference, &trials, 1, "current");
    assert_ne!(d.verdict, "current", "{}", d.explanation);
    assert_ne!(d.verdict, "wind", "{}", d.explanation);
    // the yaw channel's harmonic statistic is as large as before; on one course it is read
    // across the courses instead, where the manoeuvre's own mismatch is the same on each
    assert!(current.statistic > 30.0, "{current:?}");
    assert!(
        current.evidence.contains("read across the courses instead"),
        "{current:?}"
    );
    assert!(current.p_value > 0.01, "{current:?}");
}

#[test]
fn without_an_anemometer_records_that_each_hold_one_course_show_no_wind() {
    // the built-in ship's effect-free ±20° zig-zags against its PRBS reference, seed 2, the
    // anemometer's columns dropped: with the yaw channel's harmonics not counted, wind's one
    // remaining channel was the speed over ground's heading harmonics, which the speed lost
    // in the turns of one course shows as well (the second harmonic read `wind` at p =
    // 2.5e-5). The yaw channel is now read across the courses, and shows no moment that
    // changes with the course
    let (model, reference, trials) =
        without_anemometer(zig_zags_against_prbs(crate::sim::WorldKind::Lng, 2));
    let (d, wind) = diagnosed_at(&model, &reference, &trials, 2, "wind");
    assert_eq!(d.verdict, "none", "{}", d.explanation);
    assert!(wind.p_value > 0.01, "{wind:?}");
    assert!(
        wind.evidence.contains("read across the courses instead"),
        "{wind:?}"
    );
}

/// The records with the anemometer's columns dropped.
fn without_anemometer(
    (model, mut reference, mut trials): (Model, Vec<Record>, Vec<Record>),
) -> (Model, Vec<Record>, Vec<Record>) {
    for r in reference.iter_mut().chain(trials.iter_mut()) {
        assert!(r.wind_speed.is_some() && r.cog.is_some(), "{}", r.name);
        r.wind_speed = None;
        r.wind_angle = None;
    }
    (model, reference, trials)
}

#[test]
fn on_records_that_each_hold_one_course_a_wind_is_told_from_a_steady_moment_across_the_courses() {
    // the built-in ship's ±20° zig-zags against its PRBS reference without an anemometer,
    // each trial record on its own course: a wind pushes the ship one way on one course and
    // the other way on another, a steady moment the same way on every course. Over one
    // course the heading harmonics cannot tell either from the manoeuvre's own mismatch; the
    // records' error offsets on their own courses, compared across the courses, can
    // (measured: the wind at p = 1.9e-246, 4.0e-5 as (offset, slope) pairs on 4 df; the
    // steady moment's records alike, p = 0.72, courses 46° apart)
    use crate::sim::WorldKind;
    let mut rows = Vec::new();
    for hidden in [EffectKind::Wind, EffectKind::Bias] {
        let (model, reference, trials) =
            without_anemometer(zig_zags_against_prbs_in(WorldKind::Lng, 1, Some(hidden)));
        let (d, wind) = diagnosed_at(&model, &reference, &trials, 1, "wind");
        assert!(
            wind.evidence.contains("read across the courses instead"),
            "{wind:?}"
        );
        rows.push((hidden, d.verdict, wind.p_value));
    }
    println!("{rows:?}");
    assert_eq!(rows[0].1, "wind", "{rows:?}");
    assert!(rows[0].2 < 1e-3, "{rows:?}");
    assert_eq!(rows[1].1, "bias", "{rows:?}");
    assert!(rows[1].2 > 0.01, "{rows:?}");
}

#[test]
fn on_records_that_each_hold_one_course_a_current_is_read_across_their_courses() {
    // Mariner's ±20° zig-zags against a zig-zag reference without an anemometer, each
    // record on its own course. Within one course a current is each record's own offset of
    // the ground velocity, which the heading harmonics give to the record's intercept; across
    // the courses it is one vector on the earth, seen along and across each heading. Before,
    // the hidden 1.47 m/s current read `none` (`run.sh --trial-input zigzag:20/20 --ref-input
    // zigzag:20/20`: 3 of 3 seeds). Measured: 1.464 m/s at p = 2.4e-9; effect-free p = 0.34,
    // the smallest current shown 0.078 m/s
    use crate::sim::WorldKind;
    let mut rows = Vec::new();
    for hidden in [Some(EffectKind::Current), None] {
        let (model, reference, trials) =
            without_anemometer(zig_zags_against(WorldKind::Mariner, 1, hidden, true));
        let (d, current) = diagnosed_at(&model, &reference, &trials, 1, "current");
        assert!(
            current
                .evidence
                .contains("read across the courses (each record's mean"),
            "{current:?}"
        );
        rows.push((
            d.verdict,
            current.p_value,
            current.parameter,
            current.resolution,
        ));
    }
    println!("{rows:?}");
    assert_eq!(rows[0].0, "current", "{rows:?}");
    assert!(rows[0].1 < 1e-4, "{rows:?}");
    let speed = rows[0].2.unwrap();
    assert!((speed - 1.47).abs() < 0.1, "{rows:?}");
    // the effect-free trials: no current, and the smallest one they would show far under
    // the hidden one
    assert_eq!(rows[1].0, "none", "{rows:?}");
    assert!(rows[1].1 > 0.01, "{rows:?}");
    assert!(rows[1].3.unwrap() < 0.2, "{rows:?}");
}

#[test]
fn a_current_on_long_records_is_read_from_the_records_whole() {
    // Mariner logged at 4 Hz: three 30-minute records of 7 200 samples per set, so the
    // statistics run on blocks of 2 000 samples (`WINDOW`). The ground track's calibration
    // compares each record with the others of its set; read on the blocks it compared
    // 500-second pieces of one record, which span too few headings: the current's
    // resolution was 3.1 m/s and a 1.4 m/s current went unnamed (verdict `none`)
    use crate::sim::{World, WorldKind};
    let w = World::new(WorldKind::Mariner, None).unwrap();
    let sail = |effects: Vec<SimEffect>, noise: [f64; 3], seeds: &[u64]| {
        let sc = Scenario {
            ts: 0.25,
            n_samples: 7200,
            input: w.default_input(),
            effects,
            ..Scenario::default()
        };
        sailed(&w, sc, noise, seeds)
    };
    let reference = sail(Vec::new(), [0.02, 0.1, 0.0], &[900, 901, 902]);
    let model = identify(&reference);
    let current = w.hidden(EffectKind::Current, 1.0);
    let trials = sail(vec![current], [0.03, 0.2, 0.02], &[100, 101, 102]);
    let d = diagnose(&model, &reference, &trials, &[], &DiagnoseConfig::default()).unwrap();
    println!("{}\n{:?}", d.explanation, d.caveats);
    assert!(
        d.caveats
            .iter()
            .any(|c| matches!(c, Caveat::Blocks { trials: 6, .. })),
        "{:?}",
        d.caveats
    );
    // 21 600 samples a set at 4 Hz: read whole at 0.5 s, and the caveat says so
    assert!(
        d.caveats.iter().any(|c| matches!(
            c,
            Caveat::Blocks {
                resample_s: Some(s),
                ..
            } if *s == 0.5
        )),
        "{:?}",
        d.caveats
    );
    assert_eq!(d.verdict, "current", "{}", d.explanation);
    // the current the ground track shows, against the one hidden
    let SimEffect::Current { speed_mps, .. } = current else {
        panic!("{current:?}")
    };
    let named = d.ranking.iter().find(|r| r.effect == "current").unwrap();
    let speed = named.parameter.unwrap();
    assert!(
        (speed - speed_mps).abs() < 0.1 * speed_mps,
        "{speed} {speed_mps}"
    );
}

/// The suite's full steady-moment case with autopilot trials on world `kind`: the reference
/// three PRBS records (seeds 900–902), the trials three autopilot records (100–102), both
/// with the anemometer and the course over ground ([`sailed`]); the model identified as `yawcast
/// identify` does, with the steady moment the reference shows; diagnosed at seed 1.
fn autopilot_bias(kind: crate::sim::WorldKind) -> super::Diagnosis {
    use crate::sim::{InputSpec, World};
    let w = World::new(kind, None).unwrap();
    let sail = |input: InputSpec, effects: Vec<SimEffect>, noise: [f64; 3], seeds: &[u64]| {
        let sc = Scenario {
            n_samples: 1800,
            input,
            effects,
            ..Scenario::default()
        };
        sailed(&w, sc, noise, seeds)
    };
    let reference = sail(
        w.default_input(),
        Vec::new(),
        [0.02, 0.1, 0.0],
        &[900, 901, 902],
    );
    let model = pem::offset::identify(&reference, &PemConfig::default())
        .unwrap()
        .0
        .model;
    let bias = w.hidden(EffectKind::Bias, 1.0);
    let trials = sail(
        w.default_autopilot(),
        vec![bias],
        [0.03, 0.2, 0.02],
        &[100, 101, 102],
    );
    let cfg = DiagnoseConfig {
        seed: 1,
        ..DiagnoseConfig::default()
    };
    diagnose(&model, &reference, &trials, &[], &cfg).unwrap()
}

#[test]
fn a_steady_moment_under_an_autopilot_is_not_read_as_a_current() {
    // trials of a ship in service: an autopilot holds each record within ±10° of its course,
    // so over the three records a yaw moment with the heading's first harmonic mimics a
    // steady one. The verdict was `current` while the ground track showed none (χ² = 0.2,
    // 2 df) and the anemometer no wind; then, once the encompassing test compared the two,
    // the steady moment. The yaw channel's harmonics are now not counted on records that
    // each hold one course: the current rests on the ground track, which shows none, and
    // the steady moment is named; read across the courses, the records' error offsets are
    // alike (+0.192 to +0.193 °/s, p = 0.72), as a steady moment's are
    let d = autopilot_bias(crate::sim::WorldKind::Lng);
    let current = d.ranking.iter().find(|r| r.effect == "current").unwrap();
    let bias = d.ranking.iter().find(|r| r.effect == "bias").unwrap();
    println!(
        "{} bias {:.1e} current {:.1e}\n{}",
        d.verdict, bias.p_value, current.p_value, d.explanation
    );
    assert!(bias.p_value < 1e-6, "{bias:?}");
    assert!(current.p_value > 0.01, "{current:?}");
    assert!(
        current.evidence.contains("read across the courses instead")
            && current
                .evidence
                .contains("its p is the ground track's alone"),
        "{current:?}"
    );
    assert_eq!(d.verdict, "bias", "{}", d.explanation);
}

#[test]
fn under_an_autopilot_a_heading_harmonic_is_judged_at_the_headings_sailed() {
    // KVLCC2's steady moment under an autopilot: the bootstrap replayed the logged commands
    // open loop, so each replicate's heading wandered over many courses, where a heading
    // harmonic is no steady moment; on the three courses the autopilot held it is one. The
    // current's null was too narrow: p = 2.2e-5 and the verdict `current`, while the ground
    // track showed none (χ² = 0.1, 2 df). Measured at the headings sailed, the current is not
    // significant (the verdict is KVLCC2's runner-up there, a dead band: the steady moment
    // itself, p = 0.06, is not). The yaw channel's harmonics are now not counted at all on
    // records that each hold one course (`zig_zags_that_each_hold_one_course_…` above), so
    // the current rests on the ground track here; the bootstrap's headings still serve
    // wherever the records do turn
    let d = autopilot_bias(crate::sim::WorldKind::Kvlcc2);
    let current = d.ranking.iter().find(|r| r.effect == "current").unwrap();
    println!(
        "{} current {:.1e}\n{}",
        d.verdict, current.p_value, d.explanation
    );
    assert!(current.p_value > 0.01, "{current:?}");
    assert_ne!(d.verdict, "current", "{}", d.explanation);
}

#[test]
fn on_a_hull_nothing_was_chosen_on_the_hidden_effect_is_named_and_nothing_else() {
    // The Seiun Maru (a fine 105 m training ship by the MMG standard method) was added to
    // the worlds after every rule and null of the diagnosis was set, to check them on a
    // hull they never saw. Sailed as the suite sails it (`bench/worlds/run.sh --worlds
    // seiun-maru`, seed 1, no anemometer): effect-free trials read `none`; a hidden wind is
    // named from the yaw channel, and a hidden slew limit from the command's effect on the
    // yaw rate. The model given is the plain linear model (`pem::identify`), without the
    // steady yaw moment the single-screw hull's reference records show: against it the
    // effect-free trials read `wind` at p = 1.7e-7 (a constant moment made heading
    // harmonics by the headings the trials sailed); the diagnosis now reads the model
    // `identify` writes for the reference, and says so
    use crate::sim::WorldKind;
    let k = WorldKind::SeiunMaru;
    let (w, reference, model) = world_reference(k);
    assert!(model.effects.is_empty());
    let cfg = DiagnoseConfig {
        seed: 1,
        ..DiagnoseConfig::default()
    };
    for (hidden, named) in [
        (None, "none"),
        (Some(EffectKind::Wind), "wind"),
        (Some(EffectKind::RateLimit), "rate-limit"),
    ] {
        let effects = hidden.map(|e| vec![w.hidden(e, 1.0)]).unwrap_or_default();
        let trials = world_records(k, effects, &[100, 101, 102]);
        let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
        println!(
            "{hidden:?}: {} ({:?})\n{}",
            d.verdict, d.then, d.explanation
        );
        assert_eq!(d.verdict, named, "{}", d.explanation);
        let Some(Caveat::ReferenceOffset { words }) = d.caveats.first() else {
            panic!("{:?}", d.caveats)
        };
        assert!(words.contains("steady yaw moment equal to -0.2"), "{words}");
        let json = serde_json::to_value(&d.caveats[0]).unwrap();
        assert_eq!(json["caveat"], "reference-offset");
    }
}

#[test]
fn a_ship_that_rolls_reads_a_steady_moment_and_not_a_current() {
    // The container ship (Son & Nomoto's four degrees of freedom: it heels in a turn, and
    // the heel turns it) was added after every rule was set. Sailed as the suite sails it
    // (seed 1), without an anemometer and with one: effect-free trials read `none`. With
    // the canonical steady moment hidden, the trials' headings, sailed unevenly, make it a
    // heading harmonic on the yaw channel, which the current's regressor reads as well as
    // the wind's; a current carries the ship, and the ground track shows none, so the
    // steady moment is named (it was named a current, with the anemometer and without)
    use crate::sim::WorldKind;
    let k = WorldKind::Container;
    let w = crate::sim::World::new(k, None).unwrap();
    let cfg = DiagnoseConfig {
        seed: 1,
        ..DiagnoseConfig::default()
    };
    for log_wind in [false, true] {
        let reference = world_records_with(k, Vec::new(), &[900, 901, 902], log_wind);
        let model = identify(&reference);
        // the smallest steady moment the effect-free trials show at the level applied
        let mut smallest = None;
        for (hidden, named) in [(None, "none"), (Some(EffectKind::Bias), "bias")] {
            let effects = hidden.map(|e| vec![w.hidden(e, 1.0)]).unwrap_or_default();
            let trials = world_records_with(k, effects, &[100, 101, 102], log_wind);
            let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
            let current = d.ranking.iter().find(|r| r.effect == "current").unwrap();
            let bias = d.ranking.iter().find(|r| r.effect == "bias").unwrap();
            let resolution = d.caveats.iter().find_map(|c| match c {
                Caveat::MomentResolution { smallest_deg } => Some(*smallest_deg),
                _ => None,
            });
            println!(
                "{hidden:?}, anemometer {log_wind}: {} ({:?}), current p {:.1e}, steady moment \
                 {:?} (resolution {resolution:?}): {}",
                d.verdict, d.then, current.p_value, bias.parameter, current.evidence
            );
            assert_eq!(d.verdict, named, "{}", d.explanation);
            assert!(current.p_value > 0.01, "{current:?}");
            if hidden.is_none() {
                // said, in degrees of rudder, where no steady moment is named
                let r = resolution.expect("moment-resolution caveat");
                assert!(r > 0.05 && r < 5.0, "{r}");
                assert!(d
                    .explanation
                    .contains("show a steady yaw moment only from about"));
                smallest = Some(r);
            } else {
                // not said where one is; the one named is larger than the smallest the
                // effect-free trials could show
                assert_eq!(resolution, None, "{:?}", d.caveats);
                let named = bias.parameter.unwrap().abs();
                assert!(named > smallest.unwrap(), "{named} vs {smallest:?}");
            }
            if hidden.is_some() {
                assert!(
                    current.evidence.contains("the ground track shows none"),
                    "{}",
                    current.evidence
                );
            }
        }
    }
}

#[test]
fn an_asymmetry_a_steady_moment_mimics_on_slow_errors_is_told_on_fast_ones() {
    // Mariner with a half-strength port/starboard asymmetry hidden, sailed as the suite
    // sails it (seed 1): on 50-step errors the asymmetry and a steady moment each add nothing
    // given the other (p = 0.43 and 0.25), and the steady moment, ahead on its 50-step
    // statistic, was named. On one-step errors, where a gear effect acts and a steady moment
    // barely shows, the asymmetry still adds given the moment (p ≈ 2·10⁻⁷) and not the other
    // way round, so it is named
    use crate::sim::WorldKind;
    let k = WorldKind::Mariner;
    let w = crate::sim::World::new(k, None).unwrap();
    // the suite's reference: less gyro and heading noise than the trials, no speed noise
    let sc = Scenario {
        n_samples: 1800,
        input: w.default_input(),
        noise: NoiseSpec {
            gyro_std_degps: 0.02,
            heading_std_deg: 0.1,
            speed_std_mps: 0.0,
        },
        ..Scenario::default()
    };
    let reference = w.simulate_many(&sc, &[900, 901, 902]).unwrap();
    let model = identify(&reference);
    let hidden = vec![w.hidden(EffectKind::Asymmetry, 0.5)];
    let trials = world_records_with(k, hidden, &[100, 101, 102], false);
    let cfg = DiagnoseConfig {
        seed: 1,
        ..DiagnoseConfig::default()
    };
    let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
    let asym = d.ranking.iter().find(|r| r.effect == "asymmetry").unwrap();
    println!("{} ({:?}): {}", d.verdict, d.then, asym.evidence);
    assert_eq!(d.verdict, "asymmetry", "{}", d.explanation);
    assert!(
        asym.evidence
            .contains("on 50-step errors neither adds given the other"),
        "{}",
        asym.evidence
    );
    assert!(
        asym.evidence.contains("given bias, asymmetry still adds"),
        "{}",
        asym.evidence
    );
}

#[test]
fn a_tanker_of_a_third_family_reads_its_effects_and_says_what_wind_it_cannot_see() {
    // The Esso Osaka (Van Berlekom & Goddard: the rudder in the propeller's race, hull
    // forces in modulus form) was added after every rule was set. Sailed as the suite sails
    // it (seed 1, no anemometer): effect-free trials read `none` and say the smallest
    // once-per-turn moment their errors would show. The canonical wind, which the rudder
    // holds course against with 0.71° varying once per turn
    // (`a_winds_moment_varies_with_heading_mostly_once_per_turn`), lies under it and reads
    // `none` with the same caveat; a slew limit in the gear is named
    use crate::sim::WorldKind;
    let k = WorldKind::EssoOsaka;
    let (w, reference, model) = world_reference(k);
    let cfg = DiagnoseConfig {
        seed: 1,
        ..DiagnoseConfig::default()
    };
    for (hidden, named) in [
        (None, "none"),
        (Some(EffectKind::Wind), "none"),
        (Some(EffectKind::RateLimit), "rate-limit"),
    ] {
        let effects = hidden.map(|e| vec![w.hidden(e, 1.0)]).unwrap_or_default();
        let trials = world_records(k, effects, &[100, 101, 102]);
        let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
        let wind = d.ranking.iter().find(|r| r.effect == "wind").unwrap();
        let caveat = d.caveats.iter().find_map(|c| match c {
            Caveat::WindResolution { smallest_deg } => Some(*smallest_deg),
            _ => None,
        });
        println!(
            "{hidden:?}: {} ({:?}); wind p {:.2}, resolution {:?}",
            d.verdict, d.then, wind.p_value, wind.resolution
        );
        assert_eq!(d.verdict, named, "{}", d.explanation);
        // said where wind is not named, and the same figure as the ranking's
        let r = caveat.expect("wind-resolution caveat");
        assert_eq!(wind.resolution, Some(r));
        assert!(r > 0.71 && r < 20.0, "{r}");
        assert!(d
            .explanation
            .contains("show a yaw moment varying once per turn of heading"));
        let json = serde_json::to_value(&d.caveats).unwrap();
        assert!(
            json.as_array()
                .unwrap()
                .iter()
                .any(|c| c["caveat"] == "wind-resolution" && c["smallest_deg"].as_f64() == Some(r)),
            "{json}"
        );
    }
}

#[test]
fn a_wind_too_weak_to_turn_the_ship_is_told_from_a_current_by_its_set() {
    // The container ship with the canonical wind at half strength and no anemometer, sailed
    // as the suite sails it (seed 3): the wind's yaw moment is under what the yaw channel
    // shows (p = 1), and its drag and leeway set the ship over ground, so it was named a
    // current. A uniform current sets the ship alike along and across its heading; the
    // hull answers a wind's drag with its surge resistance and its side force with its
    // sway resistance, several times stiffer, so the wind's set lies mostly along the
    // heading (across it 0.2 of it here, a hidden current's 1.0–1.1): `wind`. The hidden
    // current at half strength stays `current`
    use crate::sim::WorldKind;
    let k = WorldKind::Container;
    let (w, reference, model) = world_reference(k);
    let cfg = DiagnoseConfig {
        seed: 3,
        ..DiagnoseConfig::default()
    };
    for (hidden, named) in [(EffectKind::Wind, "wind"), (EffectKind::Current, "current")] {
        let trials = world_records(k, vec![w.hidden(hidden, 0.5)], &[300, 301, 302]);
        let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
        let wind = d.ranking.iter().find(|r| r.effect == "wind").unwrap();
        println!(
            "{hidden:?}: {} ({:?}): {}",
            d.verdict, d.then, wind.evidence
        );
        assert_eq!(d.verdict, named, "{}", d.explanation);
        let told = wind
            .evidence
            .contains("the ground track's set is not a uniform current's");
        assert_eq!(told, hidden == EffectKind::Wind, "{}", wind.evidence);
        let leeway = d
            .caveats
            .iter()
            .any(|c| matches!(c, Caveat::CurrentOrLeeway { .. }));
        assert_eq!(leeway, hidden == EffectKind::Current, "{:?}", d.caveats);
    }
}

#[test]
fn a_gear_somewhat_slower_than_the_references_is_told_from_a_dead_time() {
    // The container ship's own gear slews at 2.5 °/s; a hidden slew limit at half strength,
    // 2.1 °/s, lags its PRBS steps by a near-constant time. On a grid of 12 rates (the
    // nearest 2.37) it read `dead-time`; on the grid of 25 its rate is read within its
    // uncertainty, and a hidden dead time stays a dead time
    use crate::sim::{SimEffect, WorldKind};
    let k = WorldKind::Container;
    let (w, reference, model) = world_reference(k);
    let cfg = DiagnoseConfig {
        seed: 1,
        ..DiagnoseConfig::default()
    };
    for kind in [EffectKind::RateLimit, EffectKind::DeadTime] {
        let hidden = w.hidden(kind, 0.5);
        let trials = world_records(k, vec![hidden], &[100, 101, 102]);
        let d = diagnose(&model, &reference, &trials, &[], &cfg).unwrap();
        let named = d.ranking.iter().find(|r| r.effect == d.verdict).unwrap();
        println!(
            "{hidden:?}: {} {:?} ± {:?}",
            d.verdict, named.parameter, named.parameter_uncertainty
        );
        assert_eq!(d.verdict, kind.name(), "{}", d.explanation);
        if let SimEffect::RateLimit { rate_degps } = hidden {
            let (p, u) = (
                named.parameter.unwrap(),
                named.parameter_uncertainty.unwrap(),
            );
            assert!(
                (p - rate_degps).abs() <= u && u < 0.5,
                "{p} ± {u} against {rate_degps}"
            );
        }
    }
}

//! The f64 heading/track predictor against the firmware's f32 one (called, never
//! re-implemented) on a simulated record with a current.

use super::*;
use crate::io::nav::ground_velocity;
use crate::sim::{simulate_with_nav, Scenario, Ship, SimEffect};
use yawcast_firmware::track::{NavMeasurement, Tracker};
use yawcast_shared::model::{ModelSpec, Units};

#[test]
fn f64_twin_follows_the_firmware_to_centimetres() {
    let sc = Scenario::with_effect(SimEffect::Current {
        speed_mps: 0.5,
        towards_deg: 40.0,
    });
    let (rec, sn) = simulate_with_nav(&Ship::default_lng(), &sc, 4).unwrap();
    let psi = rec.psi.clone().unwrap();
    let sog = rec.speed.clone().unwrap();
    let mut spec = TrackSpec::new(1.0, 1.28, true).unwrap();
    spec.sway = -0.072;
    spec.speed_loss = 0.009;
    // any valid yaw-rate model: only its sample time and gyro offset matter here
    let m = ModelSpec::new(
        2,
        1.0,
        &[-0.7, -1.5],
        &[0.1, -0.05],
        &[0.3, -0.2],
        Units::default(),
        &[yawcast_shared::model::Effect::GyroBias { d_y: 0.05 }],
    )
    .unwrap();
    let mut fw = Tracker::new(&m, &spec).unwrap();
    let mut host = Tracker64::new(1.0, f64::from(0.05f32), &spec);
    let mut worst = [0.0f64; 3];
    for t in 0..rec.len() - 20 {
        let v = ground_velocity(sog[t], sn.cog_deg[t]);
        let fix = (t % 10 == 0).then_some([sn.north_m[t], sn.east_m[t]]);
        let nav = NavMeasurement {
            velocity: Some([v[0] as f32, v[1] as f32]),
            fix: fix.map(|f| [f[0] as f32, f[1] as f32]),
        };
        fw.update(rec.y[t] as f32, Some(psi[t] as f32), &nav);
        host.update(rec.y[t], Some(psi[t]), Some(v), fix);
        let rates: Vec<f64> = rec.y[t + 1..t + 20].to_vec();
        let rates32: Vec<f32> = rates.iter().map(|r| *r as f32).collect();
        let mut out = [[0.0f32; 3]; 20];
        fw.predict_into(&mut out, &rates32).unwrap();
        let want = host.predict(&rates);
        for (a, b) in out.iter().zip(&want) {
            for j in 0..3 {
                worst[j] = worst[j].max((f64::from(a[j]) - b[j]).abs());
            }
        }
    }
    // heading to a thousandth of a degree, positions (a few hundred metres from the
    // origin, f32 there resolves 0.03 mm) to a centimetre over the whole record
    assert!(worst[0] < 1e-3, "heading {worst:?}");
    assert!(worst[1] < 0.01 && worst[2] < 0.01, "position {worst:?}");
    // and the current found by both is the simulated one
    let c = host.state().current;
    let towards = 40f64.to_radians();
    assert!((c[0] - 0.5 * towards.cos()).abs() < 0.1, "{c:?}");
    assert!((c[1] - 0.5 * towards.sin()).abs() < 0.1, "{c:?}");
}

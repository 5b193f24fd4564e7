// Chrono's side of verti's single-wheel soil test (docs/src/results/chrono.md, "One wheel rolling
// on soil"; crates/verti-sim/src/contact/soil.rs, `a_rolling_wheel_sinks_as_chronos_scm_wheel`).
//
// One rigid HMMWV wheel (a cylinder of radius 0.467 m and width 0.254 m, as HMMWV_RigidTire) on
// flat SCM soil with Verti-Bench's parameters (0.1 m grid, one moving patch 1.0 x 0.6 x 1.0 m on
// the wheel, bulldozing 55/1/5/10 unless BULLDOZE is 0). A carrier is moved along x at V by a
// linear motor and is free to move vertically, without rotating; the wheel, 60 kg of the LOAD
// (N) that bears on it, is spun by a motor at V/(r(1 - SLIP)). After 2 s at rest and a 1-s run-up
// it prints, as one JSON line, the mean sinkage r - z of the hub, the drive motor's force and
// the spin motor's torque between x = 25 and 45 m (at V = 0: over the last 0.5 s at rest).
// RIG_NODES=1 also prints the pressure of the nodes around the wheel at the end.
//
// Build against the Chrono 9.0.1 build of ../shared/chrono-anchor (build.sh), as make_driver.sh
// builds vb_drive, with wheel_rig.cpp in place of vb_drive.cpp.
//
// usage: wheel_rig SOIL V SLIP LOAD [STEP] [BULLDOZE 0|1] [TRAJ]   (SOIL: snow, mud, sand)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include "chrono/physics/ChBodyEasy.h"
#include "chrono/physics/ChLinkMate.h"
#include "chrono/physics/ChLinkMotorLinearSpeed.h"
#include "chrono/physics/ChLinkMotorRotationSpeed.h"
#include "chrono/physics/ChSystemNSC.h"
#include "chrono/functions/ChFunctionConst.h"
#include "chrono/functions/ChFunctionSetpoint.h"
#include "chrono_vehicle/terrain/SCMTerrain.h"
using namespace chrono;
using namespace chrono::vehicle;

int main(int argc, char** argv) {
    if (argc < 5) { std::fprintf(stderr, "usage: wheel_rig SOIL V SLIP LOAD [STEP] [BULLDOZE] [TRAJ]\n"); return 2; }
    std::string soil = argv[1];
    double v = std::atof(argv[2]), slip = std::atof(argv[3]), load = std::atof(argv[4]);
    double step = argc > 5 ? std::atof(argv[5]) : 5e-3;
    bool bulldoze = argc > 6 ? std::atoi(argv[6]) != 0 : true;
    FILE* traj = argc > 7 ? std::fopen(argv[7], "w") : nullptr;
    const double r = 0.467, w = 0.254, m_wheel = 60.0;
    ChSystemNSC sys;
    sys.SetGravitationalAcceleration(ChVector3d(0, 0, -9.81));
    sys.SetCollisionSystemType(ChCollisionSystem::Type::BULLET);
    sys.SetNumThreads(1, 1, 1);

    auto ground = chrono_types::make_shared<ChBody>();
    ground->SetFixed(true);
    sys.AddBody(ground);
    auto carrier = chrono_types::make_shared<ChBody>();
    carrier->SetMass(load / 9.81 - m_wheel);
    carrier->SetInertiaXX(ChVector3d(10, 10, 10));
    carrier->SetPos(ChVector3d(0, 0, r));
    sys.AddBody(carrier);
    auto mat = chrono_types::make_shared<ChContactMaterialNSC>();
    auto wheel = chrono_types::make_shared<ChBodyEasyCylinder>(ChAxis::Y, r, w, 1000, false, true, mat);
    wheel->SetMass(m_wheel);
    wheel->SetInertiaXX(ChVector3d(2, 4, 2));
    wheel->SetPos(ChVector3d(0, 0, r));
    sys.AddBody(wheel);

    auto plane = chrono_types::make_shared<ChLinkMateGeneric>(false, true, false, true, true, true);
    plane->Initialize(carrier, ground, ChFrame<>(ChVector3d(0, 0, r), QUNIT));
    sys.AddLink(plane);
    auto drive = chrono_types::make_shared<ChLinkMotorLinearSpeed>();
    drive->SetGuideConstraint(ChLinkMotorLinear::GuideConstraint::FREE);
    drive->Initialize(carrier, ground, ChFrame<>(ChVector3d(0, 0, r), Q_ROTATE_Z_TO_X));
    auto vfun = chrono_types::make_shared<ChFunctionSetpoint>();
    drive->SetSpeedFunction(vfun);
    sys.AddLink(drive);
    auto spin = chrono_types::make_shared<ChLinkMotorRotationSpeed>();
    spin->Initialize(wheel, carrier, ChFrame<>(ChVector3d(0, 0, r), Q_ROTATE_Z_TO_Y));
    auto wfun = chrono_types::make_shared<ChFunctionSetpoint>();
    spin->SetSpeedFunction(wfun);
    sys.AddLink(spin);

    SCMTerrain scm(&sys, false);
    if (soil == "snow") scm.SetSoilParameters(0.2e6, 0, 1.1, 0, 30, 0.01, 4e7, 3e4);
    else if (soil == "mud") scm.SetSoilParameters(2e6, 0, 1.1, 0, 30, 0.01, 2e8, 3e4);
    else if (soil == "sand") scm.SetSoilParameters(5301e3, 102e3, 0.793, 1.3e3, 31.1, 0.012, 4e8, 3e4);
    else { std::fprintf(stderr, "soil?\n"); return 2; }
    if (bulldoze) {
        scm.EnableBulldozing(true);
        scm.SetBulldozingParameters(55, 1, 5, 10);
    }
    scm.SetPlane(ChCoordsys<>(ChVector3d(28, 0, 0), QUNIT));
    scm.Initialize(64.0, 4.0, 0.1);
    scm.AddMovingPatch(wheel, ChVector3d(0, 0, 0), ChVector3d(1.0, 0.6, 1.0));

    double t = 0, settle = 2.0, ramp = 1.0;
    double sum_z = 0, sum_dbp = 0, sum_tq = 0, sum_w = 0;
    int n = 0;
    while (true) {
        double vt = t < settle ? 0 : (t < settle + ramp ? v * (t - settle) / ramp : v);
        double x = carrier->GetPos().x();
        if (x > 45 || t > 200) break;
        // spin = (1 + slip) v / r  as a driving slip s = 1 - v/(w r)
        double wt = vt / (r * (1 - slip));
        vfun->SetSetpoint(vt, t);
        wfun->SetSetpoint(wt, t);
        scm.Synchronize(t);
        sys.DoStepDynamics(step);
        t += step;
        double z = wheel->GetPos().z();
        if (traj && (int)std::lround(t / step) % 10 == 0)
            std::fprintf(traj, "%.3f %.4f %.5f %.2f %.2f %.4f\n", t, x, r - z, drive->GetMotorForce(), spin->GetMotorTorque(), wheel->GetAngVelParent().y());
        bool measure = v > 0 ? (x > 25) : (t > settle - 0.5 && t < settle);
        if (measure) {
            sum_z += r - z; sum_dbp += drive->GetMotorForce(); sum_tq += spin->GetMotorTorque(); sum_w += wheel->GetAngVelParent().y(); n++;
        }
        if (v == 0 && t >= settle) break;
    }
    if (std::getenv("RIG_NODES")) {
        for (int j = -3; j <= 3; j++) {
            for (int i = -6; i <= 6; i++) {
                auto ni = scm.GetNodeInfo(ChVector3d(carrier->GetPos().x() + i * 0.1, j * 0.1, 0));
                std::fprintf(stderr, "%7.0f ", ni.sigma);
            }
            std::fprintf(stderr, "\n");
        }
        std::fprintf(stderr, "hits %d x %.4f\n", scm.GetNumRayHits(), carrier->GetPos().x());
    }
    std::printf("{\"soil\":\"%s\",\"v\":%g,\"slip\":%g,\"load\":%g,\"step\":%g,\"bulldoze\":%d,\"sinkage\":%.4f,\"motor_force\":%.1f,\"torque\":%.1f,\"spin\":%.3f,\"n\":%d}\n",
                soil.c_str(), v, slip, load, step, bulldoze ? 1 : 0, sum_z / n, sum_dbp / n, sum_tq / n, sum_w / n, n);
    if (traj) std::fclose(traj);
    return 0;
}

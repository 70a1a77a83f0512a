// --input-points: which points of the user's body the follower sees (issue 12). A three-point
// recording (head and hands) always gives the three-point follower; a full-body input gives it
// with --input-points head,hands, which keeps only the head and the wrists (to test three points
// against full-body truth).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "duet/base/result.h"
#include "duet/features/feature_spec.h"
#include "duet/follow/tracker.h"
#include "duet/io/motion_file.h"
#include "duet/motion/arms_forward.h"
#include "duet/motion/device_points.h"

namespace duet::app {

inline constexpr const char* kInputPointsHelp =
    "Which points of the input the follower sees: full (the whole body) or head,hands (what a "
    "headset and two controllers give). Default: head,hands for a three-point input, else full";

// The values of --input-points ("full" and "head,hands"; without "full" for duet convert
// --points), with an error that says "head,hands" is one value: CLI11's IsMember printed the
// choices as {full,head,hands}, which reads as three.
CLI::Validator input_points_choice(bool with_full);

// `option` is "", "full" or "head,hands". With head,hands on a full-body motion, `motion` becomes
// its three points. Errors when the input cannot give what is asked.
Result<InputPoints> choose_input_points(const std::string& option, LoadedMotion& motion);

// An option of three device offsets FORWARD,UP,GRIP in cm (duet/motion/device_points.h), each
// within 30 cm.
CLI::Option* add_offsets_cm_option(CLI::App& app, const std::string& name, std::vector<double>& cm,
                                   const std::string& help);
// --device-offsets-cm FORWARD,UP,GRIP (duet/motion/device_points.h): where a headset's eyes and
// the controllers' grips sit against the head and wrist joints. `what` ends the help: what the
// command does with them.
CLI::Option* add_device_offsets_option(CLI::App& app, std::vector<double>& cm,
                                       const std::string& what);
// The option's numbers as offsets; empty: none.
DevicePointOffsets device_offsets_from_cm(const std::vector<double>& cm);
// --head-height M: the height of the input's head point (the headset's, for a headset) with the
// user standing straight: a height calibration, FollowSession::set_head_height's unit for three
// points; 0 when not given.
CLI::Option* add_head_height_option(CLI::App& app, double& metres);
// Three points followed without --head-height: when the head stood clearly higher later than in
// the recording's first second, the body's size learnt at the start was too small (a dance that
// starts low) and the first seconds were followed at the wrong size. Then a note saying so and
// which --head-height to give (the input's head point: the eyes when `offsets` were taken out);
// else nullopt.
std::optional<std::string> head_height_note(const Clip& points, const JointRoles& roles,
                                            const DevicePointOffsets& offsets);
// Errors when --head-height is given (metres > 0) for a follower that does not see three points.
Status check_head_height_applies(double metres, InputPoints points);
// Three points followed without --calibration: when the rig's posture offset the follower learnt
// is another body's (CalibrationAdvice, duet/live/calibration_advice.h), a note saying that
// --calibration would give it from the first frame; else nullopt (also for under a second of
// frames whose offset had been learnt a while).
std::optional<std::string> calibration_note(std::span<const FollowResult> results,
                                            double frame_rate_hz);
// --calibration FILE: a recording of the user standing straight with both arms held straight
// forward (arms_forward.h): the body's calibration for three points.
CLI::Option* add_calibration_option(CLI::App& app, std::string& path);
struct BodyCalibration {
  double head_height_m = 0.0;  // the head joint's median height: standing straight
  ArmsForward arms_forward;
};
// Reads it: a three-point recording (the device offsets `cm` taken out, as from the input) or a
// full-body motion (its head and wrists). Errors name the file and what is wrong with the pose.
Result<BodyCalibration> read_body_calibration(const std::string& path,
                                              const std::vector<double>& device_offsets_cm);
// Errors when --calibration is given for a follower that does not see three points.
Status check_calibration_applies(const std::string& path, InputPoints points);

// Takes the offsets `cm` out of `motion`, a recording of three points as the devices reported
// them (its units from metres_per_unit). Errors when the motion is not three points (a full body,
// or three points made from one, are at the joints already).
Status take_out_device_offsets(const std::vector<double>& cm, LoadedMotion& motion);

}  // namespace duet::app

#include "duet/live/young_offset_confidence.h"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace duet {
namespace {

constexpr int kInputs = 2;  // InputPoints::kFullBody, kHeadHands
// Band b holds values in [edges[b - 1], edges[b]); must match the fitting script.
constexpr float kOffsetEdges[] = {0.03f, 0.06f, 0.1f};      // RMS per posture dimension
constexpr float kLearntEdges[] = {1.0f, 2.0f, 3.0f, 5.0f};  // seconds; kSettledS on: identity
constexpr int kOffsetBands = static_cast<int>(std::size(kOffsetEdges)) + 1;
constexpr int kLearntBands = static_cast<int>(std::size(kLearntEdges)) + 1;
// Knots at the tracker's confidence 0, 0.1, ..., 0.9, 0.95, 0.99, 1.
constexpr float kKnots[] = {0.0f, 0.1f, 0.2f, 0.3f,  0.4f,  0.5f, 0.6f,
                            0.7f, 0.8f, 0.9f, 0.95f, 0.99f, 1.0f};
constexpr int kKnotCount = static_cast<int>(std::size(kKnots));

// Fitted by scripts/fit_young_offset_confidence.py on `duet eval --trackers hmm
// --no-partner-metrics --rigs all --takes 0,1,...,13 --seed S --non-dance none --frames-csv` for
// seeds 11 and 23: the whole body with the cases clean, tempo-slow, tempo-fast, improv,
// improv-pause, noise, 30hz-noisy, improv-30hz-noisy, harsh, suit-drift, tilted, dropouts,
// body-size, late-frames; three points (`--input-points head,hands`) with clean, tempo-fast,
// improv, improv-library, noise, improv-30hz-noisy, harsh, suit-drift. The reported evaluation
// uses seeds 1 and 7.
constexpr float kTable[kInputs][kOffsetBands][kLearntBands][kKnotCount] = {
    // whole body: fitted on full_11.csv, full_23.csv
    {
        {
            // offset band 0, learnt band 0: 74674 frames, 0.937 claimed, 0.935 right
            {0.2678f, 0.2678f, 0.4477f, 0.5208f, 0.5336f, 0.5488f, 0.6539f, 0.6605f, 0.6814f,
             0.9227f, 0.9382f, 0.9796f, 0.9989f},
            // offset band 0, learnt band 1: 68633 frames, 0.962 claimed, 0.979 right
            {0.5405f, 0.5405f, 0.5405f, 0.5553f, 0.5702f, 0.5852f, 0.5965f, 0.8597f, 0.9210f,
             0.9808f, 0.9857f, 0.9941f, 0.9999f},
            // offset band 0, learnt band 2: 63372 frames, 0.992 claimed, 0.999 right
            {0.2174f, 0.2174f, 0.2174f, 0.2174f, 0.2846f, 0.6250f, 0.8956f, 0.9411f, 0.9866f,
             0.9989f, 0.9990f, 1.0000f, 1.0000f},
            // offset band 0, learnt band 3: 120847 frames, 0.995 claimed, 0.997 right
            {0.3006f, 0.3006f, 0.3006f, 0.3006f, 0.3640f, 0.6100f, 0.6284f, 0.6999f, 0.8490f,
             0.9962f, 0.9983f, 1.0000f, 1.0000f},
            // offset band 0, learnt band 4: 172676 frames, 0.996 claimed, 0.997 right
            {0.1608f, 0.1608f, 0.1608f, 0.1608f, 0.2066f, 0.3226f, 0.6867f, 0.7895f, 0.9457f,
             0.9963f, 0.9992f, 0.9998f, 1.0000f},
        },
        {
            // offset band 1, learnt band 0: 31570 frames, 0.949 claimed, 0.853 right
            {0.0442f, 0.0442f, 0.0782f, 0.2901f, 0.2948f, 0.2995f, 0.3244f, 0.3781f, 0.4925f,
             0.7301f, 0.7859f, 0.8266f, 0.9665f},
            // offset band 1, learnt band 1: 33979 frames, 0.955 claimed, 0.901 right
            {0.0726f, 0.0726f, 0.1372f, 0.3278f, 0.3462f, 0.3608f, 0.3791f, 0.6701f, 0.7591f,
             0.8222f, 0.8595f, 0.8797f, 0.9814f},
            // offset band 1, learnt band 2: 33733 frames, 0.990 claimed, 0.982 right
            {0.2542f, 0.2542f, 0.2542f, 0.2542f, 0.4428f, 0.6127f, 0.7492f, 0.8305f, 0.9199f,
             0.9629f, 0.9702f, 0.9784f, 0.9878f},
            // offset band 1, learnt band 3: 69919 frames, 0.994 claimed, 0.996 right
            {0.5182f, 0.5182f, 0.5182f, 0.5182f, 0.5554f, 0.5955f, 0.7137f, 0.8192f, 0.9083f,
             0.9898f, 0.9961f, 0.9979f, 0.9996f},
            // offset band 1, learnt band 4: 112192 frames, 0.996 claimed, 0.997 right
            {0.2427f, 0.2427f, 0.2427f, 0.2427f, 0.2459f, 0.3550f, 0.7641f, 0.8369f, 0.8442f,
             0.9513f, 0.9704f, 0.9980f, 1.0000f},
        },
        {
            // offset band 2, learnt band 0: 6563 frames, 0.923 claimed, 0.283 right
            {0.0084f, 0.0084f, 0.0084f, 0.0208f, 0.0477f, 0.0676f, 0.0883f, 0.1161f, 0.1438f,
             0.2896f, 0.3058f, 0.3156f, 0.3156f},
            // offset band 2, learnt band 1: 6469 frames, 0.936 claimed, 0.436 right
            {0.0078f, 0.0078f, 0.0200f, 0.1197f, 0.1794f, 0.2031f, 0.2268f, 0.2460f, 0.2485f,
             0.3136f, 0.4077f, 0.4616f, 0.4616f},
            // offset band 2, learnt band 2: 5791 frames, 0.963 claimed, 0.702 right
            {0.2044f, 0.2044f, 0.2044f, 0.2044f, 0.2165f, 0.2309f, 0.2454f, 0.2598f, 0.2945f,
             0.3544f, 0.3814f, 0.4680f, 0.8513f},
            // offset band 2, learnt band 3: 11243 frames, 0.987 claimed, 0.946 right
            {0.5543f, 0.5543f, 0.5543f, 0.5543f, 0.5652f, 0.5916f, 0.6181f, 0.6445f, 0.6710f,
             0.6974f, 0.7103f, 0.7931f, 0.9690f},
            // offset band 2, learnt band 4: 17937 frames, 0.998 claimed, 0.996 right
            {0.5926f, 0.5926f, 0.5926f, 0.5926f, 0.6273f, 0.6699f, 0.7126f, 0.7553f, 0.7980f,
             0.8406f, 0.8687f, 0.9211f, 0.9982f},
        },
        {
            // offset band 3, learnt band 0: 186 frames: as the tracker says
            {0.0000f, 0.1000f, 0.2000f, 0.3000f, 0.4000f, 0.5000f, 0.6000f, 0.7000f, 0.8000f,
             0.9000f, 0.9500f, 0.9900f, 1.0000f},
            // offset band 3, learnt band 1: 1013 frames, 0.930 claimed, 0.415 right
            {0.1005f, 0.1005f, 0.1005f, 0.1005f, 0.1005f, 0.1005f, 0.1005f, 0.1019f, 0.1142f,
             0.1264f, 0.1325f, 0.2786f, 0.6792f},
            // offset band 3, learnt band 2: 1751 frames, 0.934 claimed, 0.608 right
            {0.0351f, 0.0351f, 0.1380f, 0.1682f, 0.1803f, 0.1916f, 0.2017f, 0.2118f, 0.2219f,
             0.2315f, 0.2343f, 0.2619f, 0.8483f},
            // offset band 3, learnt band 3: 3556 frames, 0.982 claimed, 0.862 right
            {0.2500f, 0.2500f, 0.3029f, 0.3341f, 0.3350f, 0.3359f, 0.3369f, 0.3378f, 0.3394f,
             0.3444f, 0.4078f, 0.5870f, 0.9463f},
            // offset band 3, learnt band 4: 5444 frames, 0.998 claimed, 0.999 right
            {0.9880f, 0.9880f, 0.9880f, 0.9880f, 0.9880f, 0.9880f, 0.9880f, 0.9880f, 0.9880f,
             0.9880f, 0.9880f, 0.9970f, 1.0000f},
        },
    },
    // head and hands: fitted on points_11.csv, points_23.csv
    {
        {
            // offset band 0, learnt band 0: 33385 frames, 0.808 claimed, 0.756 right
            {0.3006f, 0.3006f, 0.3006f, 0.3210f, 0.3753f, 0.3832f, 0.4667f, 0.6222f, 0.7674f,
             0.8753f, 0.8764f, 0.9638f, 0.9976f},
            // offset band 0, learnt band 1: 21593 frames, 0.943 claimed, 0.981 right
            {0.4634f, 0.4634f, 0.4634f, 0.4634f, 0.8572f, 0.8662f, 0.8955f, 0.9274f, 0.9503f,
             0.9716f, 0.9805f, 0.9961f, 1.0000f},
            // offset band 0, learnt band 2: 20378 frames, 0.985 claimed, 0.997 right
            {0.7857f, 0.7857f, 0.7857f, 0.7857f, 0.8148f, 0.8515f, 0.8966f, 0.9433f, 0.9517f,
             0.9861f, 0.9949f, 0.9986f, 0.9996f},
            // offset band 0, learnt band 3: 40852 frames, 0.983 claimed, 0.993 right
            {0.5473f, 0.5473f, 0.5473f, 0.5473f, 0.8394f, 0.8528f, 0.9406f, 0.9494f, 0.9582f,
             0.9608f, 0.9621f, 0.9981f, 1.0000f},
            // offset band 0, learnt band 4: 65403 frames, 0.985 claimed, 0.996 right
            {0.7107f, 0.7107f, 0.7107f, 0.7107f, 0.8317f, 0.8502f, 0.9037f, 0.9620f, 0.9652f,
             0.9789f, 0.9857f, 0.9976f, 1.0000f},
        },
        {
            // offset band 1, learnt band 0: 22180 frames, 0.919 claimed, 0.520 right
            {0.1171f, 0.1171f, 0.1171f, 0.1171f, 0.1787f, 0.1940f, 0.2263f, 0.2628f, 0.3932f,
             0.3949f, 0.3957f, 0.4458f, 0.8778f},
            // offset band 1, learnt band 1: 19760 frames, 0.934 claimed, 0.777 right
            {0.1197f, 0.1197f, 0.1197f, 0.1197f, 0.3466f, 0.3629f, 0.3713f, 0.4021f, 0.6781f,
             0.7019f, 0.7073f, 0.7699f, 0.9508f},
            // offset band 1, learnt band 2: 17863 frames, 0.960 claimed, 0.850 right
            {0.2208f, 0.2208f, 0.2208f, 0.2208f, 0.2208f, 0.2377f, 0.2801f, 0.3843f, 0.4413f,
             0.5102f, 0.5584f, 0.8896f, 0.9876f},
            // offset band 1, learnt band 3: 31557 frames, 0.970 claimed, 0.921 right
            {0.2215f, 0.2215f, 0.2215f, 0.2215f, 0.3282f, 0.3642f, 0.4101f, 0.4212f, 0.4325f,
             0.4889f, 0.5000f, 0.9482f, 0.9977f},
            // offset band 1, learnt band 4: 40884 frames, 0.980 claimed, 0.976 right
            {0.3124f, 0.3124f, 0.3124f, 0.3124f, 0.5509f, 0.6217f, 0.7277f, 0.7553f, 0.7665f,
             0.7853f, 0.7947f, 0.9906f, 1.0000f},
        },
        {
            // offset band 2, learnt band 0: 20847 frames, 0.873 claimed, 0.279 right
            {0.1196f, 0.1196f, 0.1196f, 0.1196f, 0.1300f, 0.1392f, 0.1485f, 0.1578f, 0.1671f,
             0.1774f, 0.1829f, 0.2163f, 0.6824f},
            // offset band 2, learnt band 1: 26400 frames, 0.854 claimed, 0.327 right
            {0.1357f, 0.1357f, 0.1357f, 0.1357f, 0.1357f, 0.1357f, 0.1367f, 0.1382f, 0.1398f,
             0.1414f, 0.1607f, 0.3598f, 0.7689f},
            // offset band 2, learnt band 2: 22932 frames, 0.888 claimed, 0.534 right
            {0.1614f, 0.1614f, 0.1614f, 0.1614f, 0.1697f, 0.1980f, 0.2082f, 0.2175f, 0.2221f,
             0.2438f, 0.2943f, 0.5554f, 0.9296f},
            // offset band 2, learnt band 3: 37870 frames, 0.933 claimed, 0.784 right
            {0.1804f, 0.1804f, 0.1804f, 0.1804f, 0.1969f, 0.2186f, 0.2374f, 0.2967f, 0.3032f,
             0.3259f, 0.4573f, 0.8233f, 0.9885f},
            // offset band 2, learnt band 4: 42011 frames, 0.957 claimed, 0.894 right
            {0.2132f, 0.2132f, 0.2132f, 0.2132f, 0.2348f, 0.3032f, 0.3396f, 0.3507f, 0.3617f,
             0.4491f, 0.5264f, 0.9280f, 0.9971f},
        },
        {
            // offset band 3, learnt band 0: 9606 frames, 0.766 claimed, 0.192 right
            {0.0960f, 0.0960f, 0.0960f, 0.0960f, 0.0960f, 0.0960f, 0.0960f, 0.0970f, 0.0985f,
             0.1000f, 0.1007f, 0.1703f, 0.7778f},
            // offset band 3, learnt band 1: 8384 frames, 0.813 claimed, 0.328 right
            {0.0510f, 0.0510f, 0.0510f, 0.0510f, 0.0510f, 0.0510f, 0.0523f, 0.0544f, 0.0718f,
             0.1129f, 0.1439f, 0.4094f, 0.9664f},
            // offset band 3, learnt band 2: 5560 frames, 0.909 claimed, 0.585 right
            {0.1469f, 0.1469f, 0.1469f, 0.1469f, 0.1469f, 0.1469f, 0.1582f, 0.1713f, 0.1844f,
             0.1962f, 0.2019f, 0.6464f, 0.9656f},
            // offset band 3, learnt band 3: 12103 frames, 0.896 claimed, 0.781 right
            {0.1052f, 0.1052f, 0.1052f, 0.1052f, 0.1753f, 0.2155f, 0.2537f, 0.2572f, 0.2641f,
             0.3229f, 0.4023f, 0.9020f, 0.9983f},
            // offset band 3, learnt band 4: 28947 frames, 0.958 claimed, 0.927 right
            {0.1784f, 0.1784f, 0.1784f, 0.1784f, 0.2294f, 0.2839f, 0.4091f, 0.4628f, 0.4652f,
             0.6173f, 0.7154f, 0.9751f, 0.9998f},
        },
    },
};

int band_of(float value, const float* edges, int edge_count) {
  int band = 0;
  while (band < edge_count && value >= edges[band]) ++band;  // NaN: band 0
  return band;
}

}  // namespace

float YoungOffsetConfidence::apply(float confidence, float offset_rms, float learnt_s,
                                   InputPoints points) noexcept {
  const float c = std::isfinite(confidence) ? std::clamp(confidence, 0.0f, 1.0f) : 0.0f;
  if (!(learnt_s < kSettledS)) return c;  // settled (or NaN)
  const int input = points == InputPoints::kHeadHands ? 1 : 0;
  const float* row = kTable[input][band_of(offset_rms, kOffsetEdges, kOffsetBands - 1)]
                           [band_of(learnt_s, kLearntEdges, kLearntBands - 1)];
  const int k =
      std::clamp(static_cast<int>(std::upper_bound(kKnots, kKnots + kKnotCount, c) - kKnots) - 1, 0,
                 kKnotCount - 2);
  const float t = (c - kKnots[k]) / (kKnots[k + 1] - kKnots[k]);
  return std::clamp(row[k] + std::clamp(t, 0.0f, 1.0f) * (row[k + 1] - row[k]), 0.0f, 1.0f);
}

}  // namespace duet

#include "duet/live/young_offset_confidence.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "duet/math/lookup_table.h"

namespace duet {
namespace {

constexpr int kInputs = 2;  // InputPoints::kFullBody, kHeadHands
// Band b holds values in [edges[b - 1], edges[b]); must match the fitting script.
constexpr float kOffsetEdges[] = {0.03f, 0.06f, 0.1f};      // RMS per posture dimension
constexpr float kLearntEdges[] = {1.0f, 2.0f, 3.0f, 5.0f};  // seconds; kSettledS on: identity
constexpr int kOffsetBands = static_cast<int>(std::size(kOffsetEdges)) + 1;
constexpr int kLearntBands = static_cast<int>(std::size(kLearntEdges)) + 1;

// Fitted by scripts/fit_young_offset_confidence.py on `duet eval --trackers hmm
// --no-partner-metrics --rigs all --takes 0,1,...,13 --seed S --non-dance none --frames-csv` for
// seeds 11, 23, 31 and 41: the whole body with the cases clean, tempo-slow, tempo-fast, improv,
// improv-pause, noise, 30hz-noisy, improv-30hz-noisy, harsh, suit-drift, tilted, dropouts,
// body-size, late-frames; three points (`--input-points head,hands`) with clean, tempo-fast,
// improv, improv-library, noise, improv-30hz-noisy, harsh, suit-drift. The reported evaluation
// uses seeds 1 and 7.
constexpr float kTable[kInputs][kOffsetBands][kLearntBands][kConfidenceKnotCount] = {
    // whole body: fitted on full_11.csv, full_23.csv, full_31.csv, full_41.csv
    {
        {
            // offset band 0, learnt band 0: 151866 frames, 0.926 claimed, 0.930 right
            {0.1435f, 0.1435f, 0.4661f, 0.5012f, 0.5662f, 0.6041f, 0.6922f, 0.7078f, 0.7340f,
             0.9175f, 0.9410f, 0.9833f, 0.9990f},
            // offset band 0, learnt band 1: 137468 frames, 0.962 claimed, 0.980 right
            {0.5000f, 0.5000f, 0.5000f, 0.5189f, 0.5561f, 0.5933f, 0.6192f, 0.8597f, 0.9247f,
             0.9772f, 0.9854f, 0.9876f, 0.9999f},
            // offset band 0, learnt band 2: 126776 frames, 0.993 claimed, 0.999 right
            {0.3562f, 0.3562f, 0.3562f, 0.3562f, 0.3744f, 0.8226f, 0.9144f, 0.9425f, 0.9708f,
             0.9980f, 0.9992f, 0.9998f, 1.0000f},
            // offset band 0, learnt band 3: 242684 frames, 0.996 claimed, 0.998 right
            {0.3241f, 0.3241f, 0.3241f, 0.3241f, 0.4697f, 0.6410f, 0.6986f, 0.7141f, 0.8602f,
             0.9979f, 0.9989f, 0.9990f, 1.0000f},
            // offset band 0, learnt band 4: 346891 frames, 0.996 claimed, 0.997 right
            {0.2281f, 0.2281f, 0.2281f, 0.2281f, 0.2411f, 0.2680f, 0.5946f, 0.7415f, 0.8453f,
             0.9873f, 0.9961f, 0.9991f, 1.0000f},
        },
        {
            // offset band 1, learnt band 0: 62236 frames, 0.947 claimed, 0.860 right
            {0.0830f, 0.0830f, 0.1668f, 0.3176f, 0.3180f, 0.3184f, 0.3414f, 0.3890f, 0.5026f,
             0.7257f, 0.8089f, 0.8338f, 0.9695f},
            // offset band 1, learnt band 1: 66306 frames, 0.957 claimed, 0.913 right
            {0.0993f, 0.0993f, 0.1216f, 0.3901f, 0.3972f, 0.3986f, 0.3997f, 0.7172f, 0.8500f,
             0.8566f, 0.8890f, 0.9171f, 0.9824f},
            // offset band 1, learnt band 2: 65891 frames, 0.991 claimed, 0.983 right
            {0.2222f, 0.2222f, 0.2338f, 0.2703f, 0.4429f, 0.6854f, 0.7488f, 0.8088f, 0.8825f,
             0.9649f, 0.9695f, 0.9760f, 0.9888f},
            // offset band 1, learnt band 3: 138172 frames, 0.994 claimed, 0.998 right
            {0.5684f, 0.5684f, 0.5684f, 0.5691f, 0.5795f, 0.5899f, 0.7985f, 0.8632f, 0.9345f,
             0.9910f, 0.9975f, 0.9987f, 0.9997f},
            // offset band 1, learnt band 4: 224690 frames, 0.996 claimed, 0.997 right
            {0.2914f, 0.2914f, 0.2914f, 0.2914f, 0.3015f, 0.3212f, 0.8039f, 0.8559f, 0.8753f,
             0.9647f, 0.9791f, 0.9982f, 1.0000f},
        },
        {
            // offset band 2, learnt band 0: 13757 frames, 0.921 claimed, 0.307 right
            {0.0346f, 0.0346f, 0.0346f, 0.0534f, 0.1245f, 0.1644f, 0.1756f, 0.1867f, 0.2183f,
             0.3067f, 0.3221f, 0.3325f, 0.3325f},
            // offset band 2, learnt band 1: 13881 frames, 0.939 claimed, 0.466 right
            {0.1268f, 0.1268f, 0.1301f, 0.1894f, 0.2454f, 0.2788f, 0.2865f, 0.2894f, 0.3406f,
             0.4384f, 0.4683f, 0.4900f, 0.4900f},
            // offset band 2, learnt band 2: 12734 frames, 0.960 claimed, 0.721 right
            {0.3010f, 0.3010f, 0.3010f, 0.3015f, 0.3063f, 0.3110f, 0.3158f, 0.3379f, 0.3958f,
             0.5083f, 0.5244f, 0.5568f, 0.8113f},
            // offset band 2, learnt band 3: 25425 frames, 0.962 claimed, 0.909 right
            {0.5222f, 0.5222f, 0.5222f, 0.5223f, 0.5226f, 0.5229f, 0.5232f, 0.5235f, 0.5239f,
             0.5420f, 0.5723f, 0.7549f, 0.9617f},
            // offset band 2, learnt band 4: 35884 frames, 0.998 claimed, 0.997 right
            {0.7143f, 0.7143f, 0.7143f, 0.7179f, 0.7421f, 0.7662f, 0.7904f, 0.8308f, 0.8783f,
             0.9145f, 0.9202f, 0.9636f, 0.9990f},
        },
        {
            // offset band 3, learnt band 0: 696 frames, 0.839 claimed, 0.231 right
            {0.0000f, 0.0000f, 0.0000f, 0.0000f, 0.0317f, 0.0757f, 0.1197f, 0.1637f, 0.2077f,
             0.2320f, 0.2337f, 0.2350f, 0.3237f},
            // offset band 3, learnt band 1: 2111 frames, 0.924 claimed, 0.547 right
            {0.1136f, 0.1136f, 0.1136f, 0.1414f, 0.1725f, 0.2037f, 0.2348f, 0.2659f, 0.2935f,
             0.2956f, 0.2966f, 0.5255f, 0.7272f},
            // offset band 3, learnt band 2: 3306 frames, 0.946 claimed, 0.690 right
            {0.0361f, 0.0361f, 0.0863f, 0.1094f, 0.1325f, 0.1555f, 0.1786f, 0.2017f, 0.2195f,
             0.2319f, 0.2380f, 0.3539f, 0.8741f},
            // offset band 3, learnt band 3: 6517 frames, 0.957 claimed, 0.869 right
            {0.3139f, 0.3139f, 0.3146f, 0.3201f, 0.3256f, 0.3312f, 0.3367f, 0.3422f, 0.3477f,
             0.3797f, 0.4098f, 0.5865f, 0.9557f},
            // offset band 3, learnt band 4: 10407 frames, 0.996 claimed, 0.997 right
            {0.9379f, 0.9379f, 0.9379f, 0.9379f, 0.9379f, 0.9379f, 0.9379f, 0.9379f, 0.9452f,
             0.9598f, 0.9670f, 0.9774f, 0.9991f},
        },
    },
    // head and hands: fitted on points_11.csv, points_23.csv, points_31.csv, points_41.csv
    {
        {
            // offset band 0, learnt band 0: 66822 frames, 0.807 claimed, 0.765 right
            {0.3037f, 0.3037f, 0.3037f, 0.3317f, 0.4016f, 0.4254f, 0.4818f, 0.6981f, 0.7763f,
             0.8560f, 0.8719f, 0.9683f, 0.9983f},
            // offset band 0, learnt band 1: 42429 frames, 0.941 claimed, 0.978 right
            {0.4578f, 0.4578f, 0.4578f, 0.4578f, 0.7774f, 0.7830f, 0.8468f, 0.9094f, 0.9438f,
             0.9736f, 0.9830f, 0.9978f, 1.0000f},
            // offset band 0, learnt band 2: 39774 frames, 0.984 claimed, 0.994 right
            {0.7097f, 0.7097f, 0.7097f, 0.7097f, 0.7413f, 0.7784f, 0.9203f, 0.9298f, 0.9345f,
             0.9673f, 0.9861f, 0.9985f, 0.9997f},
            // offset band 0, learnt band 3: 81449 frames, 0.985 claimed, 0.995 right
            {0.6301f, 0.6301f, 0.6301f, 0.6301f, 0.8097f, 0.8353f, 0.9509f, 0.9659f, 0.9705f,
             0.9784f, 0.9827f, 0.9988f, 0.9999f},
            // offset band 0, learnt band 4: 131471 frames, 0.986 claimed, 0.995 right
            {0.7337f, 0.7337f, 0.7337f, 0.7337f, 0.7537f, 0.7855f, 0.9054f, 0.9295f, 0.9379f,
             0.9446f, 0.9479f, 0.9985f, 1.0000f},
        },
        {
            // offset band 1, learnt band 0: 43220 frames, 0.918 claimed, 0.543 right
            {0.1298f, 0.1298f, 0.1298f, 0.1304f, 0.2047f, 0.2105f, 0.2176f, 0.3337f, 0.4061f,
             0.4136f, 0.4240f, 0.4663f, 0.9005f},
            // offset band 1, learnt band 1: 39480 frames, 0.939 claimed, 0.799 right
            {0.1577f, 0.1577f, 0.1577f, 0.1577f, 0.3584f, 0.3873f, 0.3987f, 0.5127f, 0.6862f,
             0.7234f, 0.7431f, 0.7835f, 0.9599f},
            // offset band 1, learnt band 2: 35960 frames, 0.962 claimed, 0.862 right
            {0.2640f, 0.2640f, 0.2640f, 0.2640f, 0.2640f, 0.2650f, 0.2716f, 0.3644f, 0.4225f,
             0.5041f, 0.5398f, 0.8790f, 0.9838f},
            // offset band 1, learnt band 3: 62710 frames, 0.973 claimed, 0.928 right
            {0.2490f, 0.2490f, 0.2490f, 0.2490f, 0.2938f, 0.3376f, 0.4350f, 0.4373f, 0.4505f,
             0.4821f, 0.5515f, 0.9495f, 0.9960f},
            // offset band 1, learnt band 4: 79921 frames, 0.984 claimed, 0.982 right
            {0.4371f, 0.4371f, 0.4371f, 0.4371f, 0.5760f, 0.6376f, 0.7188f, 0.7608f, 0.7773f,
             0.8144f, 0.8329f, 0.9888f, 1.0000f},
        },
        {
            // offset band 2, learnt band 0: 42115 frames, 0.867 claimed, 0.263 right
            {0.1308f, 0.1308f, 0.1308f, 0.1308f, 0.1401f, 0.1437f, 0.1473f, 0.1509f, 0.1539f,
             0.1561f, 0.1572f, 0.2271f, 0.6646f},
            // offset band 2, learnt band 1: 52396 frames, 0.862 claimed, 0.346 right
            {0.1518f, 0.1518f, 0.1518f, 0.1518f, 0.1518f, 0.1518f, 0.1521f, 0.1537f, 0.1553f,
             0.1570f, 0.1578f, 0.3789f, 0.7711f},
            // offset band 2, learnt band 2: 45422 frames, 0.894 claimed, 0.549 right
            {0.1595f, 0.1595f, 0.1595f, 0.1595f, 0.1766f, 0.1940f, 0.2080f, 0.2129f, 0.2131f,
             0.2569f, 0.2993f, 0.5952f, 0.9206f},
            // offset band 2, learnt band 3: 74779 frames, 0.936 claimed, 0.785 right
            {0.1650f, 0.1650f, 0.1650f, 0.1650f, 0.1818f, 0.1975f, 0.2114f, 0.2557f, 0.2750f,
             0.3142f, 0.3545f, 0.8378f, 0.9892f},
            // offset band 2, learnt band 4: 82297 frames, 0.956 claimed, 0.892 right
            {0.2047f, 0.2047f, 0.2047f, 0.2047f, 0.2161f, 0.2614f, 0.3485f, 0.3762f, 0.3864f,
             0.4530f, 0.5273f, 0.9239f, 0.9957f},
        },
        {
            // offset band 3, learnt band 0: 18939 frames, 0.769 claimed, 0.215 right
            {0.0000f, 0.0000f, 0.0000f, 0.0155f, 0.0447f, 0.0739f, 0.1031f, 0.1215f, 0.1273f,
             0.1331f, 0.1361f, 0.1821f, 0.7904f},
            // offset band 3, learnt band 1: 17282 frames, 0.814 claimed, 0.339 right
            {0.0657f, 0.0657f, 0.0657f, 0.0657f, 0.0657f, 0.0657f, 0.0690f, 0.0735f, 0.0777f,
             0.1447f, 0.1550f, 0.3868f, 0.9527f},
            // offset band 3, learnt band 2: 12120 frames, 0.907 claimed, 0.565 right
            {0.1149f, 0.1149f, 0.1149f, 0.1149f, 0.1149f, 0.1149f, 0.1276f, 0.1423f, 0.1571f,
             0.1808f, 0.1979f, 0.6247f, 0.9615f},
            // offset band 3, learnt band 3: 25191 frames, 0.912 claimed, 0.784 right
            {0.1034f, 0.1034f, 0.1034f, 0.1034f, 0.1600f, 0.2042f, 0.2441f, 0.2505f, 0.2574f,
             0.2874f, 0.3990f, 0.8759f, 0.9962f},
            // offset band 3, learnt band 4: 59804 frames, 0.960 claimed, 0.925 right
            {0.1995f, 0.1995f, 0.1995f, 0.1995f, 0.2683f, 0.2989f, 0.3652f, 0.4958f, 0.5189f,
             0.5650f, 0.6029f, 0.9777f, 0.9978f},
        },
    },
};

}  // namespace

float YoungOffsetConfidence::apply(float confidence, float offset_rms, float learnt_s,
                                   InputPoints points) noexcept {
  const float c = std::isfinite(confidence) ? std::clamp(confidence, 0.0f, 1.0f) : 0.0f;
  if (!(learnt_s < kSettledS)) return c;  // settled (or NaN)
  const int input = points == InputPoints::kHeadHands ? 1 : 0;
  const float* row =
      kTable[input][band_of(offset_rms, kOffsetEdges)][band_of(learnt_s, kLearntEdges)];
  return interpolate_knots(kConfidenceKnots, std::span<const float>(row, kConfidenceKnotCount), c);
}

}  // namespace duet

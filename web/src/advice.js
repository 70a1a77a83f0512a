// What the server advises (`stats`.advice, docs/protocol.md), in words for the status panel:
// a body calibration when the follower has learnt that the user's hands sit elsewhere against
// the head than the library's dancers' (duet/live/calibration_advice.h).

/**
 * The text to show for a `stats` message's `advice` ('' for none). `headset`: the server follows
 * this viewer's headset (hello's source_kind "xr"), where the two-grip hold calibrates; other
 * three-point sources are calibrated on the server's command line.
 */
export function adviceText(advice, headset) {
  const calibrate = advice?.calibrate;
  if (!calibrate) return '';
  const offset = Number(calibrate.rig_offset);
  const learnt = Number.isFinite(offset) ? ` (learnt offset ${offset.toFixed(3)})` : '';
  return `Your body holds its hands elsewhere than the library's dancers${learnt}, so you are ` +
    'followed less surely until the follower has learnt it. ' +
    (headset
      ? 'Calibrate: stand straight with both arms held straight forward and hold both grips for a second.'
      : 'Calibrate: duet serve --calibration POSE.csv (a second of you standing straight, arms held straight forward).');
}

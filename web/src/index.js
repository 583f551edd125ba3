// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap: the PFAP receiver (draft-ietf-avt-rtp-pfap-00) for browsers and Node, bit-exact with
// libpfap. An ES module with no dependencies: import it from a served directory as is.
export { RtpError, makeRtp, parseRtp } from './rtp.js';
export { DecodeError, EncodeError, decodePayload, encodePayload } from './payload.js';
export { FapState } from './fap_state.js';
export { RecoveryReceiver } from './recovery.js';
export { ARPABET_ALPHABET, Viseme, findAlphabet, findPhoneme, findSymbol } from './phoneme_table.js';
export { ANGLE_UNIT, FAP_UNITS, addExpressions, expressionWeight, fapValues, poseFromFaps } from './face_model.js';
export { Animator, MOUTH_EASE_NS, visemeShape } from './animator.js';
export { AnimationFrames } from './animation_frames.js';
export { Style, renderFace } from './renderer.js';
export { DEFAULT_CLOCK_RATE, PfapReceiver } from './receiver.js';
export { OCULUS_VISEMES, OCULUS_VISEME_ALPHABET, OCULUS_VISEME_TABLE, VISEME_LOOKAHEAD_MS, VisemeDetector, parseVisemeModel } from './viseme_detector.js';
export {
  COVERAGE_STEPS, Curve, FAP_COUNT, FIRST_EXPRESSION_INDEX, MAX_AMPLITUDE, MAX_F0_HZ, MAX_FAP_INDEX,
  MAX_PHONEME_DURATION_MS, MAX_TRANSITION_MS, MIN_FAP_INDEX, NS_PER_MS, f0Code, isValidFap,
  isValidPhoneme,
} from './model.js';

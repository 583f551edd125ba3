// SPDX-License-Identifier: LGPL-2.1-or-later
// Types of the pfap package (web/src/index.js). Times are nanoseconds as numbers; durations
// and transitions milliseconds; f0 Hz.

/** One FAP target: a bookmark's effect on one FAP, or a recovery entry. */
export interface Fap {
  /** 3..74; 69..74 are the expressions 1..6 */
  index: number;
  /** |amplitude| <= 2529600, in the FAP's own units */
  amplitude: number;
  /** ms, 0..16383; in a recovery entry the time still remaining at the packet's time */
  transition: number;
  /** 1 linear, 2 triangle, 3 spline */
  curve: 1 | 2 | 3;
}

export interface Phoneme {
  symbol: number;
  /** ms, 0..4095 */
  duration: number;
  /** Hz, even, 0..510 on the wire */
  f0: number;
  stress: boolean;
  wordBegin: boolean;
  endOfText: boolean;
  /** the FAPs that start with this phoneme */
  faps: Fap[];
}

export interface Packet {
  /** C = 1: a complete FAP state (recovery entries only; FAPs not listed are 0) */
  complete: boolean;
  /** previous packets covered by dynamic recovery (1, 2, 4, 7, 15, 25, 40), 0 when none */
  coverage: number;
  recovery: Fap[];
  phonemes: Phoneme[];
}

export type DecodeErrorName =
  | 'kTruncated' | 'kReservedRecoveryType' | 'kReservedInfoBits' | 'kMissingCoverage'
  | 'kFapIndexOutOfRange' | 'kAmplitudeOutOfRange' | 'kCurveZero' | 'kMissingFinalPhoneme'
  | 'kTrailingBytes' | 'kDataInCompleteRecovery' | 'kUnterminatedRecovery' | 'kEmptyPacket';

export type DecodeResult =
  | { ok: true; packet: Packet }
  | { ok: false; error: DecodeErrorName; offset: number };

export declare const DecodeError: Readonly<Record<string, DecodeErrorName>>;
export declare function decodePayload(payload: Uint8Array): DecodeResult;

export declare class EncodeError extends Error {
  status:
    | 'kInvalidFap' | 'kInvalidPhoneme' | 'kInvalidCoverage' | 'kEndOfTextNotLast'
    | 'kDataInCompleteRecovery' | 'kRecoveryWithoutKind' | 'kEmptyPacket';
}
export declare function encodePayload(packet: Packet): Uint8Array;

export interface RtpPacket {
  marker: boolean;
  payloadType: number;
  sequenceNumber: number;
  timestamp: number;
  ssrc: number;
  /** a view into the packet's bytes */
  payload: Uint8Array;
}
export declare class RtpError extends Error {}
/** Throws RtpError when the header is malformed (as gst_rtp_buffer_map refuses it). */
export declare function parseRtp(bytes: Uint8Array): RtpPacket;
export declare function makeRtp(fields: Omit<RtpPacket, 'marker'> & { marker?: boolean }): Uint8Array;

export declare class FapState {
  apply(fap: Fap, startNs: number): void;
  amplitude(index: number, timeNs: number): number;
  settled(index: number): number;
  atRest(index: number, timeNs: number): boolean;
  recoveryEntry(index: number, timeNs: number): Fap;
  reset(): void;
}

export interface ReceiveResult {
  recovery: 'none' | 'recovered' | 'complete';
  /** complete: some settled value differs from before */
  changed: boolean;
  stateWhole: boolean;
  requestComplete: boolean;
  /** packets missing before this one */
  lost: number;
}

export declare class RecoveryReceiver {
  constructor(options?: { retryNs?: number });
  retryNs: number;
  readonly state: FapState;
  readonly stateWhole: boolean;
  receive(packet: Packet, sequenceNumber: number, timeNs: number): ReceiveResult;
  lostUnknown(): void;
  reset(joinedMidStream: boolean): void;
}

export declare const Viseme: Readonly<{
  NONE: 0; PBM: 1; FV: 2; TH: 3; TD: 4; KG: 5; CH: 6; SZ: 7; NL: 8; R: 9; A: 10; E: 11; I: 12; Q: 13; U: 14;
}>;
export interface PhonemeInfo { name: string; viseme: number }
export interface PhonemeAlphabet { name: string; symbols: readonly PhonemeInfo[] }
export declare const ARPABET_ALPHABET: 'x-pfap-arpabet';
export declare function findAlphabet(name: string): PhonemeAlphabet | null;
export declare function findPhoneme(alphabet: PhonemeAlphabet, symbol: number): PhonemeInfo | null;
export declare function findSymbol(alphabet: PhonemeAlphabet, name: string): number | null;

export interface Point { x: number; y: number }
export interface Eye {
  center: Point; halfWidth: number; upperLid: number; lowerLid: number; pupil: Point; irisRadius: number;
}
/** A face projected on the picture plane, in face units (head height 1, y down). */
export interface FacePose {
  roll: number;
  headCenter: Point;
  outline: Point[];
  eyes: Eye[];
  brows: { points: Point[] }[];
  cheeks: Point[];
  cheekPuff: number[];
  nose: Point;
  outerLips: Point[];
  innerLips: Point[];
  jawOpen: number;
  /** joy, sadness, anger, fear, disgust, surprise: 0..1 */
  expressions: number[];
}
export declare const FAP_UNITS: Readonly<{ mns: number; mw: number; ens: number; es: number; irisd: number }>;
export declare const ANGLE_UNIT: number;
export declare function fapValues(): Float64Array;
export declare function expressionWeight(faps: ArrayLike<number>, e: number): number;
export declare function addExpressions(faps: Float64Array): void;
export declare function poseFromFaps(faps: ArrayLike<number>): FacePose;

export interface AnimatorEvent {
  kind: 'phoneme' | 'recovered' | 'complete';
  phoneme?: { symbol: number; duration: number };
  faps: Fap[];
}
export declare const MOUTH_EASE_NS: number;
export declare function visemeShape(viseme: number): readonly number[];
export declare class Animator {
  constructor(alphabet?: PhonemeAlphabet | null);
  alphabet: PhonemeAlphabet | null;
  readonly lastNs: number;
  readonly endNs: number;
  readonly state: FapState;
  apply(event: AnimatorEvent, timeNs: number): boolean;
  faps(timeNs: number): Float64Array;
  pose(timeNs: number): FacePose;
  describe(timeNs: number): string;
  reset(): void;
}

export declare class AnimationFrames {
  constructor();
  drawTime(now: number): number;
  intervalMs(): number;
}

export declare const Style: Readonly<{ CARTOON: 'cartoon'; LINE: 'line' }>;
export declare function renderFace(
  ctx: CanvasRenderingContext2D,
  pose: FacePose,
  options?: { style?: 'cartoon' | 'line'; width?: number; height?: number; overlay?: string },
): void;

export interface ReceiverEvent {
  kind: 'phoneme' | 'recovered' | 'complete';
  /** stream time: ns since the stream's first RTP timestamp, on its clock rate */
  timeNs: number;
  /** the first phoneme of a packet with the RTP marker bit */
  sentenceStart: boolean;
  /** the FAP state may be wrong (loss without recovery, or joined mid-stream) */
  uncertain: boolean;
  /** phoneme: its FAPs; recovered or complete: the entries */
  faps: Fap[];
  phoneme?: Omit<Phoneme, 'faps'> & { name: string | null; viseme: number | null };
}

export interface PfapReceiverOptions {
  /** RTP clock rate, default 44100 (the draft's) */
  clockRate?: number;
  /** accept only this payload type; default any */
  payloadType?: number | null;
  /** the phoneme alphabet (SDP alphabet=...), default 'x-pfap-arpabet'; null: unknown */
  alphabet?: string | null;
  /** how often to ask again for a complete state while not whole, ns of stream time */
  retryNs?: number;
  onEvent?: (event: ReceiverEvent) => void;
  /** ask the sender for a complete state (for example RTCP PLI, or a data channel message) */
  onRequestComplete?: (info: { sequenceNumber: number; ssrc: number }) => void;
  /** dropped packets, rate-limited (1st, 2nd, 4th... of a kind) */
  onWarning?: (message: string) => void;
}

export interface ReceiverStats {
  packets: number; malformedRtp: number; malformedPayload: number; otherPayloadType: number;
  late: number; phonemes: number; faps: number; lost: number; gaps: number; recovered: number;
  completeStates: number; requests: number;
}

export declare const DEFAULT_CLOCK_RATE: 44100;
export declare class PfapReceiver {
  constructor(options?: PfapReceiverOptions);
  readonly stats: ReceiverStats;
  readonly stateWhole: boolean;
  /** events received that the face has not reached yet */
  readonly pendingEvents: number;
  readonly recovery: RecoveryReceiver;
  readonly animator: Animator;
  receive(bytes: Uint8Array): ReceiverEvent[];
  lostUnknown(): void;
  advance(timeNs: number): void;
  faps(timeNs: number): Float64Array;
  pose(timeNs: number): FacePose;
  /**
   * Draws the face at timeNs; returns whether it drew: only where it differs from the face the
   * last draw left on ctx (FAPs, style, overlay, another ctx, the canvas resized), or with force
   */
  draw(ctx: CanvasRenderingContext2D, timeNs: number, options?: { style?: 'cartoon' | 'line'; overlay?: boolean; force?: boolean }): boolean;
  reset(): void;
}

export declare const Curve: Readonly<{ LINEAR: 1; TRIANGLE: 2; SPLINE: 3 }>;
export declare const COVERAGE_STEPS: readonly number[];
export declare const NS_PER_MS: 1000000;
export declare const MIN_FAP_INDEX: 3;
export declare const MAX_FAP_INDEX: 74;
export declare const FIRST_EXPRESSION_INDEX: 69;
export declare const FAP_COUNT: number;
export declare const MAX_AMPLITUDE: 2529600;
export declare const MAX_TRANSITION_MS: 16383;
export declare const MAX_PHONEME_DURATION_MS: 4095;
export declare const MAX_F0_HZ: 510;
export declare function f0Code(hz: number): number;
export declare function isValidFap(fap: Fap): boolean;
export declare function isValidPhoneme(phoneme: Phoneme): boolean;

/** The viseme detector (viseme_detector.js; align/viseme_detector.h in C++). */
export declare const OCULUS_VISEME_ALPHABET: 'x-pfap-oculus-viseme';
export declare const OCULUS_VISEMES: readonly string[];
export declare const OCULUS_VISEME_TABLE: PhonemeAlphabet;
export declare const VISEME_LOOKAHEAD_MS: number;
export interface VisemeModel { hidden1: number; hidden2: number; params: Float32Array }
export interface VisemeRun { start: number; frames: number; viseme: number }
export declare function parseVisemeModel(text: string): VisemeModel;
export declare class VisemeDetector {
  constructor(rate: number, options: { model: VisemeModel; maxRunFrames?: number; switchMargin?: number; minRunFrames?: number; trace?: number[] | null });
  readonly frames: number;
  push(samples: Float32Array | number[]): VisemeRun[];
  finish(): VisemeRun[];
}

// SPDX-License-Identifier: LGPL-2.1-or-later
// src/index.d.ts against the code, so that the two cannot drift: every export index.d.ts
// declares, with the type tsc gives it from the module that defines it (its JSDoc, checked by
// tsc --checkJs), must be assignable to the declared one. A function then accepts every
// argument the declaration allows and returns what it says; a class has every declared member
// with a compatible type; a constant has the declared value's type. An export or a function
// parameter the code leaves untyped (any) would match anything, so it is refused too.
// tests/web/meson.build type-checks this and src/ with web/tsconfig.json (test web-types); it
// is not run.
import type * as Declared from '../src/index.js';
import * as animationFrames from '../src/animation_frames.js';
import * as animator from '../src/animator.js';
import * as faceModel from '../src/face_model.js';
import * as fapState from '../src/fap_state.js';
import * as model from '../src/model.js';
import * as payload from '../src/payload.js';
import * as phonemeTable from '../src/phoneme_table.js';
import * as receiver from '../src/receiver.js';
import * as recovery from '../src/recovery.js';
import * as renderer from '../src/renderer.js';
import * as rtp from '../src/rtp.js';
import * as visemeDetector from '../src/viseme_detector.js';

type Code = typeof animationFrames & typeof animator & typeof faceModel & typeof fapState & typeof model & typeof payload &
  typeof phonemeTable & typeof receiver & typeof recovery & typeof renderer & typeof rtp &
  typeof visemeDetector;
type Declarations = typeof Declared;

type IsAny<T> = 0 extends 1 & T ? true : false;
type HasAnyParameter<T> = T extends (...args: infer P) => unknown
  ? true extends { [I in keyof P]: IsAny<P[I]> }[number] ? true : false
  : false;

// Each export that does not match, with why; never when all do.
type Mismatch = {
  [K in keyof Declarations & string]: K extends keyof Code
    ? IsAny<Code[K]> extends true ? `${K}: untyped in the code`
      : HasAnyParameter<Code[K]> extends true ? `${K}: a parameter untyped in the code`
        : Code[K] extends Declarations[K] ? never
          : `${K}: the code's type is not assignable to index.d.ts's`
    : `${K}: declared in index.d.ts, defined in no module`;
}[keyof Declarations & string];

// A type error here lists the exports that do not match ("missing the following properties").
export const mismatches: Record<Mismatch, true> = {};

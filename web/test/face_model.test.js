// SPDX-License-Identifier: LGPL-2.1-or-later
// expressionWeight against libpfap's pfap::expression_weight, the one rule pfapface's face
// and the blendshapes weigh expressions by: for amplitudes in, at the edges of and beyond
// 0..63, each expression 1..6 weighs the same, to the last bit. The one difference allowed is
// the sign of a zero: for amplitudes from -0 to the largest negative that rounds to 0 when
// divided by 63, std::clamp keeps -0 where Math.max gives +0, a weight that moves nothing
// either way.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { expressionWeight, fapValues } from '../src/index.js';
import { exportVectors } from './libpfap.js';

test('expression weights equal pfap::expression_weight\'s', () => {
  const vectors = exportVectors(['expressions']);
  assert.ok(vectors.length > 1000);
  for (const { amplitude, weight } of vectors) {
    for (let e = 1; e <= 6; ++e) {
      const faps = fapValues();
      faps[68 + e] = amplitude;
      const actual = expressionWeight(faps, e);
      assert.ok(actual === weight, `expression ${e} at ${amplitude}: ${actual}, C++ ${weight}`);
    }
  }
  // The vectors reach both clamps and the inside.
  assert.ok(vectors.some((v) => v.weight === 0 && v.amplitude < 0));
  assert.ok(vectors.some((v) => v.weight === 1 && v.amplitude > 63));
  assert.ok(vectors.some((v) => v.weight > 0 && v.weight < 1));
});

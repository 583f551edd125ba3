// SPDX-License-Identifier: LGPL-2.1-or-later
// Phoneme alphabets with the MPEG-4 viseme of each phoneme (lib/src/phoneme_table.cc).

/** The MPEG-4 visemes (ISO/IEC 14496-2, FAP 1 viseme_select), as pfap::Viseme numbers them. */
export const Viseme = Object.freeze({
  NONE: 0, // silence, and phonemes with no mouth shape of their own
  PBM: 1, // p b m: lips closed
  FV: 2, // f v
  TH: 3, // think, that
  TD: 4, // t d
  KG: 5, // k g
  CH: 6, // cheese, joy, she
  SZ: 7, // s z
  NL: 8, // n l
  R: 9, // r
  A: 10, // car
  E: 11, // bed
  I: 12, // tip
  Q: 13, // top
  U: 14, // book
});

const V = Viseme;

/** The name of x-pfap-arpabet, the `alphabet` caps field and SDP fmtp value. */
export const ARPABET_ALPHABET = 'x-pfap-arpabet';

// 0 is a pause, then the 39 ARPAbet phonemes of the CMU Pronouncing Dictionary in
// alphabetical order. Diphthongs by their first mouth shape; HH and NG with k g; ER with r;
// W with U; Y with I.
const ARPABET = Object.freeze(
  [
    ['pause', V.NONE], ['AA', V.A], ['AE', V.A], ['AH', V.A], ['AO', V.Q], ['AW', V.A], ['AY', V.A],
    ['B', V.PBM], ['CH', V.CH], ['D', V.TD], ['DH', V.TH], ['EH', V.E], ['ER', V.R], ['EY', V.E],
    ['F', V.FV], ['G', V.KG], ['HH', V.KG], ['IH', V.I], ['IY', V.I], ['JH', V.CH], ['K', V.KG],
    ['L', V.NL], ['M', V.PBM], ['N', V.NL], ['NG', V.KG], ['OW', V.Q], ['OY', V.Q], ['P', V.PBM],
    ['R', V.R], ['S', V.SZ], ['SH', V.CH], ['T', V.TD], ['TH', V.TH], ['UH', V.U], ['UW', V.U],
    ['V', V.FV], ['W', V.U], ['Y', V.I], ['Z', V.SZ], ['ZH', V.CH],
  ].map(([name, viseme]) => Object.freeze({ name, viseme })),
);

const ALPHABETS = Object.freeze({ [ARPABET_ALPHABET]: Object.freeze({ name: ARPABET_ALPHABET, symbols: ARPABET }) });

/**
 * The alphabet called `name`, or null if this library does not know it.
 * @param {string} name
 * @returns {import('./index.js').PhonemeAlphabet | null}
 */
export function findAlphabet(name) {
  return Object.prototype.hasOwnProperty.call(ALPHABETS, name) ? ALPHABETS[name] : null;
}

// An alphabet object as findAlphabet gives it, or a TypeError that says so: its name (the
// caps field's and SDP's value, ARPABET_ALPHABET) is the likely mistake.
/**
 * @param {import('./index.js').PhonemeAlphabet} alphabet
 * @param {string} caller
 * @returns {import('./index.js').PhonemeAlphabet}
 */
function checkAlphabet(alphabet, caller) {
  if (alphabet === null || typeof alphabet !== 'object' || !Array.isArray(alphabet.symbols)) {
    const given = typeof alphabet === 'string' ? `the name '${alphabet}'` : String(alphabet);
    throw new TypeError(
      `${caller}: alphabet must be a PhonemeAlphabet, as findAlphabet(name) returns it, not ${given}`,
    );
  }
  return alphabet;
}

/**
 * Symbol `symbol` of `alphabet`: its name and viseme, or null if there is no such symbol.
 * Throws TypeError when `alphabet` is not an alphabet object (its name, for example):
 * `findPhoneme(findAlphabet(ARPABET_ALPHABET), 16)`.
 * @param {import('./index.js').PhonemeAlphabet} alphabet
 * @param {number} symbol
 * @returns {{name: string, viseme: number} | null}
 */
export function findPhoneme(alphabet, symbol) {
  return checkAlphabet(alphabet, 'findPhoneme').symbols[symbol] ?? null;
}

/**
 * The symbol of the phoneme called `name` in `alphabet`, or null. Throws TypeError when
 * `alphabet` is not an alphabet object, as findPhoneme.
 * @param {import('./index.js').PhonemeAlphabet} alphabet
 * @param {string} name
 * @returns {number | null}
 */
export function findSymbol(alphabet, name) {
  const i = checkAlphabet(alphabet, 'findSymbol').symbols.findIndex((p) => p.name === name);
  return i < 0 ? null : i;
}

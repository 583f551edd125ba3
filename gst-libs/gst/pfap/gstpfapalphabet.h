/* GStreamer PFAP library
 * SPDX-License-Identifier: LGPL-2.1-or-later
 */
#ifndef __GST_PFAP_ALPHABET_H__
#define __GST_PFAP_ALPHABET_H__

#include <gst/pfap/pfap-prelude.h>

G_BEGIN_DECLS

/**
 * SECTION:gstpfapalphabet
 * @title: GstPfapAlphabet
 * @short_description: Phoneme alphabets: symbols, names and visemes
 *
 * The draft leaves the mapping of 8-bit phoneme symbols to phonemes to out-of-band
 * signalling: here the `alphabet` field of the caps (SDP `a=fmtp:<pt> alphabet=<name>`).
 * Look the alphabet up by that name, then map each event's symbol to the phoneme's name and
 * its MPEG-4 viseme (mouth shape).
 */

/**
 * GST_PFAP_ALPHABET_ARPABET:
 *
 * The name of the ARPAbet alphabet: 0 a pause, then the 39 phonemes of the CMU Pronouncing
 * Dictionary in alphabetical order, AA = 1 ... ZH = 39.
 */
#define GST_PFAP_ALPHABET_ARPABET "x-pfap-arpabet"

/**
 * GstPfapViseme:
 * @GST_PFAP_VISEME_NONE: silence, and phonemes with no mouth shape of their own
 * @GST_PFAP_VISEME_PBM: p b m: lips closed
 * @GST_PFAP_VISEME_FV: f v: lower lip to upper teeth
 * @GST_PFAP_VISEME_TH: T D (think, that): tongue between teeth
 * @GST_PFAP_VISEME_TD: t d
 * @GST_PFAP_VISEME_KG: k g
 * @GST_PFAP_VISEME_CH: tS dZ S (cheese, joy, she): lips rounded forward
 * @GST_PFAP_VISEME_SZ: s z: teeth nearly closed
 * @GST_PFAP_VISEME_NL: n l
 * @GST_PFAP_VISEME_R: r
 * @GST_PFAP_VISEME_A: A: (car): jaw open
 * @GST_PFAP_VISEME_E: e (bed)
 * @GST_PFAP_VISEME_I: I (tip): lips spread
 * @GST_PFAP_VISEME_Q: Q (top): open, rounded
 * @GST_PFAP_VISEME_U: U (book): rounded, nearly closed
 *
 * The MPEG-4 visemes (ISO/IEC 14496-2, FAP 1 viseme_select), each named by the phonemes that
 * share it.
 */
typedef enum {
  GST_PFAP_VISEME_NONE = 0,
  GST_PFAP_VISEME_PBM = 1,
  GST_PFAP_VISEME_FV = 2,
  GST_PFAP_VISEME_TH = 3,
  GST_PFAP_VISEME_TD = 4,
  GST_PFAP_VISEME_KG = 5,
  GST_PFAP_VISEME_CH = 6,
  GST_PFAP_VISEME_SZ = 7,
  GST_PFAP_VISEME_NL = 8,
  GST_PFAP_VISEME_R = 9,
  GST_PFAP_VISEME_A = 10,
  GST_PFAP_VISEME_E = 11,
  GST_PFAP_VISEME_I = 12,
  GST_PFAP_VISEME_Q = 13,
  GST_PFAP_VISEME_U = 14,
} GstPfapViseme;

/**
 * GstPfapAlphabet:
 *
 * A phoneme alphabet this library knows. Alphabets are static: copying one gives the same
 * pointer back, freeing one does nothing.
 */
typedef struct _GstPfapAlphabet GstPfapAlphabet;

#define GST_TYPE_PFAP_ALPHABET (gst_pfap_alphabet_get_type())

GST_PFAP_API
GType gst_pfap_alphabet_get_type(void);

/**
 * gst_pfap_alphabet_find:
 * @name: an alphabet's name, as the `alphabet` caps field gives it
 *
 * Returns: (transfer none) (nullable): the alphabet called @name, or %NULL if this library
 * does not know it
 */
GST_PFAP_API
const GstPfapAlphabet *gst_pfap_alphabet_find(const gchar *name);

/**
 * gst_pfap_alphabet_get_name:
 * @alphabet: a #GstPfapAlphabet
 *
 * Returns: (transfer none): its name
 */
GST_PFAP_API
const gchar *gst_pfap_alphabet_get_name(const GstPfapAlphabet *alphabet);

/**
 * gst_pfap_alphabet_get_n_symbols:
 * @alphabet: a #GstPfapAlphabet
 *
 * Returns: the number of symbols of @alphabet: symbols 0 to this minus 1 are known
 */
GST_PFAP_API
guint gst_pfap_alphabet_get_n_symbols(const GstPfapAlphabet *alphabet);

/**
 * gst_pfap_alphabet_get_phoneme_name:
 * @alphabet: a #GstPfapAlphabet
 * @symbol: a phoneme symbol
 *
 * Returns: (transfer none) (nullable): the name of phoneme @symbol ("AA"), or %NULL if
 * @alphabet has no such symbol
 */
GST_PFAP_API
const gchar *gst_pfap_alphabet_get_phoneme_name(const GstPfapAlphabet *alphabet, guint8 symbol);

/**
 * gst_pfap_alphabet_get_viseme:
 * @alphabet: a #GstPfapAlphabet
 * @symbol: a phoneme symbol
 *
 * Returns: the viseme of phoneme @symbol; %GST_PFAP_VISEME_NONE also for an unknown symbol
 */
GST_PFAP_API
GstPfapViseme gst_pfap_alphabet_get_viseme(const GstPfapAlphabet *alphabet, guint8 symbol);

/**
 * gst_pfap_alphabet_lookup_symbol:
 * @alphabet: a #GstPfapAlphabet
 * @name: a phoneme's name
 * @symbol: (out): its symbol
 *
 * Returns: whether @alphabet has a phoneme called @name
 */
GST_PFAP_API
gboolean gst_pfap_alphabet_lookup_symbol(const GstPfapAlphabet *alphabet, const gchar *name,
                                         guint8 *symbol);

G_END_DECLS

#endif /* __GST_PFAP_ALPHABET_H__ */

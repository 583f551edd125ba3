// SPDX-License-Identifier: LGPL-2.1-or-later
// Sentences for the tts tests: the Harvard sentences and sentences made to reach the rarer
// English phonemes (syllabic consonants, r-coloured vowels, flaps, glottal stops, loch).
#pragma once

namespace pfap::tts {

inline constexpr const char* kCorpus[] = {
    "The birch canoe slid on the smooth planks.",
    "Glue the sheet to the dark blue background.",
    "It's easy to tell the depth of a well.",
    "These days a chicken leg is a rare dish.",
    "Rice is often served in round bowls.",
    "The juice of lemons makes fine punch.",
    "The box was thrown beside the parked truck.",
    "The hogs were fed chopped corn and garbage.",
    "Four hours of steady work faced us.",
    "A large size in stockings is hard to sell.",
    "The boy was there when the sun rose.",
    "A rod is used to catch pink salmon.",
    "The source of the huge river is the clear spring.",
    "Kick the ball straight and follow through.",
    "Help the woman get back to her feet.",
    "A pot of tea helps to pass the evening.",
    "Smoky fires lack flame and heat.",
    "The soft cushion broke the man's fall.",
    "The salt breeze came across from the sea.",
    "The girl at the booth sold fifty bonds.",
    "Hello world. How are you today?",
    "Is this the thing that measures pleasure and leisure?",
    "Judge the vision of the azure genre with joy and choice.",
    "Thank you; the weather is rather nice, isn't it?",
    "We were worried about the yellow orange curtain.",
    "Your poor tour guide sure was bored near the pier where the air is clear.",
    "I think I thought about nothing but singing and ringing bells.",
    "The quick brown fox jumps over the lazy dog.",
    "Oil, boy, toy, coin, noise, voice and choice.",
    "Cow, now, how, loud, out, about the house, our hour, fire, tired.",
    "Bottle, little, button, kitten, water, better, butter.",
    "Who would have known the whole hole was here?",
    "She sells sea shells by the sea shore in June.",
    "Measure treasure, usual vision, beige garage.",
    "Loch, Bach, ugh, hmm, uh-huh, oh no, yeah.",
    "Nineteen ninety nine, forty two percent, three point one four.",
    "Anyway, the anyone everybody unusual ridiculous computer.",
    "Hurry, furry, mirror, error, sorry, carry, marry, merry.",
    "Cruel, fuel, jewel, dual, poet, create, idea, theatre.",
    "Of course it was, for all the world, a thing of beauty.",
};

}  // namespace pfap::tts

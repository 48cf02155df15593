"""Transcripts: everyday sentences whose keywords carry scripted semantic gestures.

Part of the corpus generator :mod:`beatlite.synth`, which no notebook teaches (``data_samples/README.md`` describes its rules).
"""

from __future__ import annotations

import numpy as np

KEYWORDS: dict[str, tuple[str, str]] = {
    # deictic
    "i": ("chest", "02_deictic_l"),
    "me": ("chest", "02_deictic_l"),
    "my": ("chest", "02_deictic_l"),
    "you": ("point_forward", "03_deictic_m"),
    "your": ("point_forward", "03_deictic_m"),
    "this": ("point_down", "04_deictic_h"),
    "here": ("point_down", "04_deictic_h"),
    # iconic
    "big": ("big", "07_iconic_h"),
    "huge": ("big", "07_iconic_h"),
    "large": ("big", "07_iconic_h"),
    "small": ("small", "06_iconic_m"),
    "little": ("small", "06_iconic_m"),
    "tiny": ("small", "06_iconic_m"),
    "round": ("circle", "05_iconic_l"),
    "circle": ("circle", "05_iconic_l"),
    "around": ("circle", "05_iconic_l"),
    "up": ("up", "06_iconic_m"),
    "high": ("up", "06_iconic_m"),
    # metaphoric
    "idea": ("idea", "08_metaphoric_l"),
    "think": ("idea", "08_metaphoric_l"),
    "future": ("future", "09_metaphoric_m"),
    "tomorrow": ("future", "09_metaphoric_m"),
    "everything": ("everything", "09_metaphoric_m"),
    "everyone": ("everything", "09_metaphoric_m"),
    "love": ("love", "10_metaphoric_h"),
    "heart": ("love", "10_metaphoric_h"),
}
"""Keyword (lower case) -> (gesture kind used by :mod:`beatlite.synth.motion`, BEAT semantic type)."""

GESTURE_KINDS = (
    "chest",
    "point_forward",
    "point_down",
    "big",
    "small",
    "circle",
    "up",
    "idea",
    "future",
    "everything",
    "love",
)
"""Every scripted semantic gesture."""

SENTENCES: tuple[str, ...] = (
    "so when i have time i like to cook something for my friends",
    "you know the kitchen in my flat is really small",
    "we bought a huge table for the garden last summer",
    "this is the place where we usually meet on sunday",
    "i think the idea came from my sister",
    "the ball was round and it rolled all around the room",
    "prices went up again and it was really high",
    "in the future i want to travel a lot more",
    "i love walking by the river in the morning",
    "you should try the little cafe near the station",
    "everything changed when we moved to the city",
    "my brother has a big dog and a tiny cat",
    "here is the map that you asked me about",
    "tomorrow we will start the project from the beginning",
    "everyone in the team had a different idea",
    "the new stadium is large and it can hold many people",
    "i usually read a book before i go to sleep",
    "you can put the keys right here on the shelf",
    "we walked in a circle because the signs were wrong",
    "the plane went up through the clouds very fast",
    "my heart was beating when i opened the letter",
    "this small thing made a big difference for me",
    "think about what you want to do next year",
    "i love the smell of fresh bread in the morning",
    "the children ran around the park all afternoon",
    "we need a bigger plan for the future of the school",
    "you were right about the weather today",
    "the office is on a high floor with a nice view",
    "i told everyone about the little party on friday",
    "this road goes all the way to the sea",
    "the cake was round and covered with chocolate",
    "my idea is to meet here every week",
    "the music was so loud that i could not hear you",
    "we cleaned everything before the guests arrived",
    "you have to turn left at the huge old tree",
    "i think it is a small price for a good life",
    "tomorrow the shop opens early in the morning",
    "the bird flew up and sat on the roof",
    "my grandmother always said that love is patient",
    "the box was tiny but it was very heavy",
    "we sat around the fire and told stories",
    "here you can see the photos from our trip",
    "this week i started to learn the guitar",
    "you always know what to say to me",
    "the lake is large and the water is very cold",
    "i made a little garden on my balcony",
    "everyone was waiting for the train in the rain",
    "the future looks bright for our small town",
    "i put my heart into this work",
    "we drove around the city looking for a parking spot",
)
"""Everyday sentences, lower case, no punctuation (as MFA writes words)."""


def sentence_order(rng: np.random.Generator) -> list[str]:
    """All sentences in a random order drawn from ``rng``.

    Parameters
    ----------
    rng : numpy.random.Generator

    Returns
    -------
    list of str
        A permutation of :data:`SENTENCES`.

    Examples
    --------
    Every sentence once, in an order fixed by the seed:

    >>> order = sentence_order(np.random.default_rng(0))
    >>> sorted(order) == sorted(SENTENCES), order == sentence_order(np.random.default_rng(0))
    (True, True)
    >>> order == sentence_order(np.random.default_rng(1))
    False
    """
    return [SENTENCES[i] for i in rng.permutation(len(SENTENCES))]

"""The lexicon of the direction cues: which words and phrases count, and as what.

Word classes of pace (faster, slower, complaints of either), of stopping, arriving and
going on; the negators and the words that end a negation's scope; the idioms counted as
phrases; chat spellings; the words around speeds given as numbers. The matching that reads
them in a request is :mod:`explaindrive.language.intent.cues`.
"""

from __future__ import annotations


def _words(text: str) -> frozenset[str]:
    return frozenset(text.split())


# Direction words. "speed" alone is neutral ("reduce the speed", "this speed scares me").
FAST_WORDS = _words(
    """fast faster fastest quick quicker quickly quicken hurry hurrying hurried rush
    rushing rushed accelerate accelerating acceleration race racing speeding
    sooner asap urgent urgently late briskly brisk throttle zoom increase raise
    hustle pronto swift swiftly speedy speedier promptly"""
)
SLOW_WORDS = _words(
    """slow slower slowly slowing slowed careful carefully cautious cautiously gentle
    gently gentler calm calmly calmer easy easier ease relax relaxed smooth smoothly
    smoother soft softly softer steady steadily comfortable comfortably safely
    decelerate decrease reduce lower less early"""
)
# Complaints about the pace: slowness words ask for more speed, recklessness words for less.
TOO_SLOW_WORDS = _words(
    """crawl crawling crawls dawdle dawdling dawdles dilly dallying snail turtle creep
    creeping crawling dragging drag poking lagging hesitating timid idling sluggish
    tortoise glacial glacier sloth funeral hearse pootling pootle lollygagging
    lollygag faffing faff dithering dither tiptoe tiptoeing"""
)
TOO_FAST_WORDS = _words(
    """reckless recklessly maniac aggressive aggressively swerving swerve tailgating
    abrupt abruptly harsh harshly jerky jerking sudden suddenly rough roughly bumpy
    slamming slam stomping tearing hurtle hurtling hurtled weaving weave zigzagging
    racetrack speedway daredevil kamikaze lurching lurch jolting jolt"""
)
# Requests to stop the trip, and words of continuing (negated: "no further").
STOP_VERBS = _words("stop halt park stopping cease")
# Verbs that forbid the action of a following gerund ("stop speeding", "quit tailgating").
QUIT_VERBS = _words("stop quit cease")
# "stop moving" halts the car, unless a manner follows ("stop driving like a maniac").
MOTION_GERUNDS = _words("moving driving going rolling travelling traveling")
HALT_FOLLOWERS = _words("now immediately instantly here please right asap")
# Common words that look like cue words with a typo but are not ("speed" is neutral).
NOT_TYPOS = _words("speed speeds sped waving wave slot slots later showing")
STOP_PHRASES: tuple[tuple[str, ...], ...] = (
    ("pull", "over"),
    ("pull", "up"),
    ("pull", "in"),
    ("let", "me", "out"),
    ("let", "me", "off"),
    ("let", "us", "out"),
    ("drop", "me"),
    ("get", "out"),
    ("get", "off"),
    ("lemme",),
    ("hop", "out"),
    ("jump", "out"),
    ("park", "it"),
)
# Stop phrases with an object are something else: "drop me a line", "pull up the map",
# "get off the phone", "get out of here!" (surprise).
_OBJECTS = _words("a an the some any your his her their my this that")
NOT_STOP_AFTER: dict[tuple[str, ...], frozenset[str]] = {
    ("drop", "me"): _OBJECTS,
    ("pull", "up"): _OBJECTS,
    ("get", "off"): _OBJECTS,
    ("get", "out"): _OBJECTS | {"of"},
}
VEHICLES = _words("car cab taxi vehicle")  # "get out of the car" is a stop
# "the rain should stop", "the bus will stop there": a mention, unless the car is meant
MODALS = _words("will would should might may must could can")
REQUEST_SUBJECTS = _words("you u ya we")
# Arrival: the passenger signals that the car is where they want to get out.
_ARRIVALS: tuple[tuple[str, ...], ...] = (
    ("we've", "arrived"),
    ("we", "have", "arrived"),
    ("this", "will", "do"),
    ("this'll", "do"),
    ("that'll", "do"),
    ("here", "is", "fine"),
    ("here's", "fine"),
    ("here", "is", "good"),
    ("here's", "good"),
    ("here", "works"),
    ("that's", "us"),
    ("this", "is", "us"),
    ("walk", "from", "here"),
    ("on", "foot", "from", "here"),
)
# Places and arrivals that are also ordinary narration ("we're here for a week", "the
# meeting ends right here at five"): they count only as the end of a clause or before an
# arrival word ("right here, please", "just here is fine").
_PLACES: tuple[tuple[str, ...], ...] = (
    ("we're", "here"),
    ("we", "are", "here"),
    ("right", "here"),
    ("just", "here"),
    ("this", "is", "it"),
    ("on", "foot"),
    ("drop", "off"),
)
ARRIVAL_PHRASES: tuple[tuple[str, ...], ...] = _ARRIVALS + _PLACES
PLACE_PHRASES = frozenset(_PLACES)
ARRIVAL_FOLLOWERS = _words(
    """please pls plz thanks thank thx ta cheers fine good great perfect ok okay mate driver
    do already now right here lol"""
)
LINK_WORDS = _words("is 's will would works")  # "right here is fine", "just here will do"
CONTINUE_WORDS = _words("further farther continue continuing anymore another beyond past")
# Words and phrases that ask to go on driving (negated: "don't carry on" asks to stop).
CONTINUE_VERBS = _words("continue continuing resume")
CONTINUE_PHRASES: tuple[tuple[str, ...], ...] = (
    ("keep", "going"),
    ("keep", "driving"),
    ("keep", "moving"),
    ("keep", "on"),
    ("carry", "on"),
    ("press", "on"),
    ("go", "on"),  # only before a clause break: not "go on foot", "go on the ring road"
    ("drive", "on"),
)
CLAUSE_FINAL_PHRASES = frozenset({("go", "on"), ("drive", "on")})
NEGATORS = _words(
    """not no don't dont never needn't neednt isn't isnt aren't arent won't wont
    shouldn't cannot can't without quit too"""
)
# "stop" before these is not a request to stop ("stop being so slow").
DETERMINERS = _words("the that this a an your those these last next sudden hard")
POSSESSIVES = _words("my our")
NOT_GERUNDS = _words(
    """something nothing anything everything thing king morning evening building parking
    ring during bring string spring ceiling"""
)
SCOPE_TOKENS = 4  # a negator governs this many following words within its clause

# Multi-word direction cues; the phrase is negated when its first word is.
FAST_PHRASES: tuple[tuple[str, ...], ...] = (
    ("speed", "up"),
    ("speed", "it", "up"),
    ("speeding", "up"),
    ("pick", "up"),
    ("pick", "it", "up"),
    ("step", "on", "it"),
    ("get", "going"),
    ("get", "moving"),
    ("get", "a", "move"),
    ("move", "it"),
    ("foot", "down"),
    ("more", "speed"),
    ("go", "go"),
    ("chop", "chop"),
    ("wriggle", "on"),
    ("shift", "on"),
    ("make", "tracks"),
    ("pedal", "to", "the", "metal"),
    ("floor", "it"),
    ("on", "the", "gas"),
    ("hit", "the", "gas"),
    ("gun", "it"),
    ("get", "cracking"),
    ("shake", "a", "leg"),
    ("on", "the", "double"),
    ("hop", "to", "it"),
    ("any", "day", "now"),
    ("got", "all", "day"),
    ("open", "her", "up"),
    ("put", "your", "foot"),
    ("right", "foot"),
    ("push", "it"),
)
SLOW_PHRASES: tuple[tuple[str, ...], ...] = (
    ("take", "your", "time"),
    ("ease", "off"),
    ("ease", "up"),
    ("back", "off"),
    ("take", "it", "easy"),
    ("rein", "it", "in"),
    ("rein", "in"),
    ("hold", "your", "horses"),
    ("cool", "it"),
    ("tone", "it", "down"),
    ("dial", "it", "back"),
    ("dial", "back"),
    ("dial", "the", "speed", "back"),
    ("down", "a", "notch"),
    ("chill", "out"),
    ("steady", "on"),
)
# Questions that call the pace needless: "what's the rush?" asks for less speed.
NEEDLESS_PACE_PHRASES: tuple[tuple[str, ...], ...] = (
    ("what's", "the", "rush"),
    ("what's", "the", "hurry"),
    ("why", "the", "rush"),
    ("why", "the", "hurry"),
    ("where's", "the", "fire"),
    ("no", "rush"),
    ("no", "hurry"),
)
# Every single cue word: the words a typo is matched against.
LEXICON: tuple[str, ...] = tuple(
    sorted(FAST_WORDS | SLOW_WORDS | TOO_SLOW_WORDS | TOO_FAST_WORDS | STOP_VERBS | {"stops"})
)
# Where a negation's scope and a clause-final phrase end.
CLAUSE_BREAKS = frozenset(".,!?;:") | {"but", "and", "because"}

# Chat spellings of cue words, too short for the typo matcher.
SLANG = {"ez": "easy", "ezy": "easy", "fst": "fast", "slw": "slow", "qck": "quick"}
# "to fast" for "too fast": "to" before one of these, then the end of the clause or a
# form of address, is the intensifier "too".
TOO_ADJECTIVES = _words("fast quick quickly slow slowly rough harsh jerky aggressive")
ADDRESS_WORDS = _words("man mate dude bro pal buddy please pls plz")

# Speeds given as numbers: a cap asks for less speed, a floor for more.
NUMBER_WORDS = {
    "ten": 10, "fifteen": 15, "twenty": 20, "thirty": 30, "forty": 40, "fifty": 50,
    "sixty": 60, "seventy": 70, "eighty": 80, "ninety": 90, "hundred": 100,
}  # fmt: skip
CAP_WORDS = _words("under below beneath max maximum")  # "keep it under 30"
OVER_WORDS = _words("over above exceed exceeding past beyond")  # negated: a cap
FLOOR_PHRASES: tuple[tuple[str, ...], ...] = (("at", "least"), ("up", "to"))
DOWN_PHRASES: tuple[tuple[str, ...], ...] = (("down", "to"), ("drop", "to"), ("back", "to"))
APPROXIMATELY = _words("about around roughly approximately maybe say")  # "down to about 40"

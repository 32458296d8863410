"""Every channel of a sensor through its own sPLL network (issue 35): the network file
(:mod:`.config`), its features (:mod:`.features`) and accuracy against time into the slide
(:mod:`.timecourse`)."""

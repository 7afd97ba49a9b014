"""The compiled core, written once against one model's dispatch (the template).

Every module here is instantiated in each model's package by
:mod:`rollingtop._compiled._instances` when that package is imported: its own text, its imports
of ``rollingtop._compiled._template`` pointed at that package, executed under the template's
file name beside a ``_dispatch`` module written for the model. Nothing imports the template
under its own name at run time: it is the source of the instances and the text that the type
checker, linters, tracebacks and coverage read.
"""

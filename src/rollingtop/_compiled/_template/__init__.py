"""The compiled core, written once against one model's dispatch (the template).

Every module here is copied into each model's package by :mod:`rollingtop._compiled._codegen`,
its imports of ``rollingtop._compiled._template`` pointed at that package, beside a ``_dispatch``
module generated for the model. Nothing imports the template at run time: it is the source of the
generated packages and the text that the type checker and linters read.
"""

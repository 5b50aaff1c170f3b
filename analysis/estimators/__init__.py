"""The latency estimators: small strategy objects behind one contract (``contract``), listed in one
registry (``registry``) in the order they run and are reported.

An estimator has a ``name`` (the ``method`` that asks for it), says whether it ``gives_interval``
(a 95 % interval), and turns the ``EstimationContext`` every estimator shares (the free swing's
signals and phases, the whole number of periods chosen, work other estimators computed) into a
``MethodResult``. Adding one is one module here and one entry in ``registry``; code outside the
package registers its own with ``registry.register_estimator``.
"""

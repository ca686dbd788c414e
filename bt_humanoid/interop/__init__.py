"""Interchange with other behaviour-tree tools: BehaviorTree.CPP v4 XML (and Groot2, Nav2), export and import.

The XML maps to and from the mission language (``btcpp_document``): an imported tree becomes the same mission
data a YAML file gives and goes through the same loader and compiler, Safety and Recovery included.
"""
